#pragma once
// tetrasand from C++: the umbrella header of the installed package (find_package(tetrasand), target
// tetrasand::tetrasand; docs/architecture.md, "Using tetrasand from C++"). It brings in the entry
// point of each stage; every library header is also installed and may be included on its own, rooted
// as in the source tree ("sampler/sample_mesh.h"). Namespaces follow the folders: ts (core),
// ts::body, ts::gpu, ts::sdf, ts::sampler, ts::sim, ts::scene, ts::exporter, ts::preview.

// Meshes: loading (OBJ, STL, PLY... through assimp), checks, mass properties; the errors thrown on bad
// input (ts::InputError carries the file and the problem).
#include "core/error.h"
#include "core/mass_properties.h"
#include "core/mesh.h"
#include "core/mesh_io.h"
// Particle rigid bodies and their files (NAME.body.json + NAME.particles.ply, docs/body-format.md).
#include "body/body_file.h"
#include "body/particle_body.h"
// Where work runs: the headless GL context and the one CPU-or-GPU rule.
#include "gpu/backend.h"
#include "gpu/context.h"
// Signed distance fields: the exact CPU field and OpenVDB / NanoVDB files.
#include "sdf/exact_sdf.h"
#include "sdf/settings.h"
#include "sdf/vdb_io.h"
// A mesh sampled into a particle rigid body (the main job).
#include "sampler/sample_mesh.h"
// The DEM engine and the scenes that drive it.
#include "scene/scene.h"
#include "scene/scene_runner.h"
#include "sim/stepper.h"
#include "sim/world.h"
// A scene written as a LAMMPS deck.
#include "export/lammps_deck.h"
// Off-screen previews of bodies.
#include "preview/body_preview.h"
