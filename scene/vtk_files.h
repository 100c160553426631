#pragma once
// The run's particles for ParaView and VTK: one XML PolyData file (.vtp) per output, binary (VTK's
// "appended raw" encoding, what vtkXMLPolyDataWriter writes by default), and a collection (.pvd) that
// lists every output with its time so ParaView plays the run as a time series. Each particle is a
// vertex cell, so the points show without a Glyph filter; its point arrays:
//   radius (m), body (index), motion (0 dynamic, 1 kinematic, 2 static), body_particles (the body's
//   particle count: 4 for a tetrahedral grain), velocity (m/s, of the sphere centre), angular_velocity
//   (rad/s, the body's, world frame), orientation (the body's unit quaternion x, y, z, w: body -> world)
//   and body_centre (m, the body's centre of mass): with the orientation, the body's frame, so a prop's
//   pose can be followed; field data TimeValue (s).
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "sim/world.h"

namespace ts::scene {

using sim::World;

// Writes `world`'s particles to `file` atomically.
void write_particles_vtp(const World& world, const std::filesystem::path& file);

// The .pvd collection of a run's .vtp outputs, rewritten whole (atomically) after each output, so it is
// valid whenever the run stops.
class VtpCollection {
 public:
  explicit VtpCollection(std::filesystem::path file) : file_(std::move(file)) {}
  // Lists `vtp` (a name in the collection's folder) at `time` (s) and rewrites the collection.
  void add(const std::string& vtp, double time);
  // A resumed run: keeps the first `outputs` entries of the collection already in its file (written
  // by the run before it stopped); an entry missing there is left out, with a warning.
  void restore(std::int64_t outputs);

 private:
  void write() const;
  struct Entry {
    double time;
    std::string file;
  };
  std::filesystem::path file_;
  std::vector<Entry> entries_;
};

}  // namespace ts::scene
