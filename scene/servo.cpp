#include "scene/servo.h"

#include <fmt/format.h>

#include <algorithm>
#include <limits>

namespace ts::scene {

double servo_target(const Servo& servo, double time) {
  const std::vector<ServoKey>& keys = servo.schedule;
  if (time <= keys.front().time) return keys.front().stress;
  if (time >= keys.back().time) return keys.back().stress;
  const auto after = std::upper_bound(keys.begin(), keys.end(), time,
                                      [](double t, const ServoKey& k) { return t < k.time; });
  const ServoKey& a = *(after - 1);
  const ServoKey& b = *after;
  return a.stress + (b.stress - a.stress) * (time - a.time) / (b.time - a.time);
}

double servo_speed(const Servo& servo, double measured, double time) {
  const double wanted = servo.gain * (servo_target(servo, time) - measured);
  return std::clamp(wanted, -servo.max_speed, servo.max_speed);
}

Eigen::Vector3d body_contact_force(const World& world, const std::vector<ContactRecord>& contacts,
                                   std::uint32_t body) {
  // A record's force acts on `particle`; its partner, when a particle, takes the opposite.
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
  for (const ContactRecord& c : contacts) {
    if (world.particles.body[c.particle] == body) force += c.force;
    if (c.partner >= 0 && world.particles.body[static_cast<std::size_t>(c.partner)] == body) force -= c.force;
  }
  return force;
}

ServoControl::ServoControl(std::vector<Servo> servos, std::vector<std::uint32_t> bodies)
    : servos_(std::move(servos)), bodies_(std::move(bodies)), samples_(servos_.size()) {}

std::int64_t ServoControl::steps_to_next(std::int64_t step) const {
  std::int64_t next = std::numeric_limits<std::int64_t>::max() / 2;
  for (const Servo& s : servos_) next = std::min(next, (step / s.every + 1) * s.every - step);
  return next;
}

bool ServoControl::update(World& world, Stepper& stepper, std::int64_t step) {
  std::vector<ContactRecord> contacts;
  bool set = false;
  for (std::size_t k = 0; k < servos_.size(); ++k) {
    const Servo& servo = servos_[k];
    if (step % servo.every != 0) continue;
    if (!set) contacts = stepper.contacts(world);  // once for all servos due now
    set = true;
    const std::uint32_t body = bodies_[k];
    ServoSample s;
    s.time = world.time;
    s.target = servo_target(servo, world.time);
    s.measured = -body_contact_force(world, contacts, body).dot(servo.direction) / servo.area;
    s.position = world.bodies.position[body].dot(servo.direction);
    s.speed = servo_speed(servo, s.measured, world.time);
    world.bodies.linear_velocity[body] = s.speed * servo.direction;
    samples_[k].push_back(s);
  }
  return set;
}

std::int64_t ServoControl::rows() const {
  std::int64_t n = 0;
  for (const auto& s : samples_) n += static_cast<std::int64_t>(s.size());
  return n;
}

std::string ServoControl::csv() const {
  std::string csv = "servo,time_s,target_Pa,measured_Pa,position_m,velocity_m_s\n";
  for (std::size_t k = 0; k < samples_.size(); ++k) {
    for (const ServoSample& s : samples_[k]) {
      csv += fmt::format("{},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g}\n", k, s.time, s.target, s.measured,
                         s.position, s.speed);
    }
  }
  return csv;
}

}  // namespace ts::scene
