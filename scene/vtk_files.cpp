#include "scene/vtk_files.h"

#include <fmt/format.h>

#include <cstdlib>
#include <fstream>
#include <regex>
#include <sstream>

#include "core/atomic_file.h"
#include "core/log.h"
#include "core/vtk_polydata.h"

namespace ts::scene {
namespace {

// Per-particle values of the body each particle belongs to, and the particles' own.
struct ParticleArrays {
  std::vector<double> points, radius, velocity, angular_velocity, orientation, body_centre;
  std::vector<std::uint32_t> body, body_particles;
  std::vector<std::uint8_t> motion;
};

ParticleArrays particle_arrays(const World& world) {
  const sim::Bodies& b = world.bodies;
  const sim::Particles& p = world.particles;
  ParticleArrays a;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const std::uint32_t k = p.body[i];
    const Eigen::Vector3d arm = b.orientation[k] * p.offset[i];
    const Eigen::Vector3d x = b.position[k] + arm;
    const Eigen::Vector3d v = b.linear_velocity[k] + b.angular_velocity[k].cross(arm);
    a.points.insert(a.points.end(), {x.x(), x.y(), x.z()});
    a.velocity.insert(a.velocity.end(), {v.x(), v.y(), v.z()});
    const Eigen::Vector3d& w = b.angular_velocity[k];
    a.angular_velocity.insert(a.angular_velocity.end(), {w.x(), w.y(), w.z()});
    const Eigen::Quaterniond& q = b.orientation[k];
    a.orientation.insert(a.orientation.end(), {q.x(), q.y(), q.z(), q.w()});
    a.body_centre.insert(a.body_centre.end(), {b.position[k].x(), b.position[k].y(), b.position[k].z()});
    a.radius.push_back(p.radius[i]);
    a.body.push_back(k);
    a.body_particles.push_back(b.particle_count[k]);
    a.motion.push_back(static_cast<std::uint8_t>(b.motion[k]));
  }
  return a;
}

}  // namespace

void write_particles_vtp(const World& world, const std::filesystem::path& file) {
  const ParticleArrays a = particle_arrays(world);
  VtpPoints vtp(a.points);
  vtp.set_time(world.time);
  vtp.add("radius", 1, a.radius);
  vtp.add("body", 1, a.body);
  vtp.add("motion", 1, a.motion);
  vtp.add("body_particles", 1, a.body_particles);
  vtp.add("velocity", 3, a.velocity);
  vtp.add("angular_velocity", 3, a.angular_velocity);
  vtp.add("orientation", 4, a.orientation);
  vtp.add("body_centre", 3, a.body_centre);
  write_file_atomically(file, vtp.bytes());
}

void VtpCollection::add(const std::string& vtp, double time) {
  entries_.push_back({time, vtp});
  write();
}

void VtpCollection::write() const {
  std::string xml =
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      "<Collection>\n";
  for (const Entry& e : entries_) {
    xml += fmt::format("<DataSet timestep=\"{:.17g}\" group=\"\" part=\"0\" file=\"{}\"/>\n", e.time, e.file);
  }
  xml += "</Collection>\n</VTKFile>\n";
  write_file_atomically(file_, xml);
}

void VtpCollection::restore(std::int64_t outputs) {
  entries_.clear();
  std::ifstream in(file_);
  std::stringstream text;
  text << in.rdbuf();
  const std::string xml = text.str();
  // Only what write() puts there: a number and an output's name (particles_NNNNNN.vtp).
  static const std::regex dataset(R"re(<DataSet timestep="([-+0-9.eE]+)" group="" part="0" file="([A-Za-z0-9_.]+)"/>)re");
  for (auto it = std::sregex_iterator(xml.begin(), xml.end(), dataset);
       it != std::sregex_iterator() && static_cast<std::int64_t>(entries_.size()) < outputs; ++it) {
    entries_.push_back({std::strtod((*it)[1].str().c_str(), nullptr), (*it)[2].str()});
  }
  if (static_cast<std::int64_t>(entries_.size()) < outputs) {
    log::warn("{}: lists {} of the {} outputs written before the run was resumed; ParaView will play the rest",
              file_.string(), entries_.size(), outputs);
  }
}

}  // namespace ts::scene
