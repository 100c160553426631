#pragma once
// A stress-controlled piston: a kinematic prop whose prescribed velocity a servo sets from the stress
// its contacts carry (scene key table [prop.servo], assets/scenes/README.md). Every `every` steps the
// runner sums the contact forces on the prop, turns them into a stress over the loaded area and sets
// the velocity along `direction` in proportion to the error against the target, capped at max_speed:
//   sigma = -(F . direction) / area        (compressive positive: the grains push back against it)
//   v     = clamp(gain (target(t) - sigma), -max_speed, max_speed) direction
// Between updates the prop moves at constant velocity, like any kinematic prop.
#include <Eigen/Core>

#include <cstdint>
#include <string>
#include <vector>

#include "sim/stepper.h"
#include "sim/world.h"
#include "scene/uses_engine.h"

namespace ts::scene {

// A point of the target stress schedule.
struct ServoKey {
  double time = 0;    // s, strictly increasing
  double stress = 0;  // Pa, compressive positive
};

struct Servo {
  // Piecewise linear in time; held before the first key and after the last. A constant target is one key.
  std::vector<ServoKey> schedule;
  double area = 0;                            // m^2, the loaded area the force is spread over
  double gain = 0;                            // (m/s)/Pa
  double max_speed = 0;                       // m/s, rate limit
  Eigen::Vector3d direction{0.0, 0.0, -1.0};  // unit: where the piston goes when it pushes
  std::int64_t every = 100;                   // steps between updates
};

// The target stress at `time` (s), Pa.
double servo_target(const Servo& servo, double time);

// The velocity (m/s, along direction) the servo commands at `time` for the measured stress (Pa).
double servo_speed(const Servo& servo, double measured, double time);

// The sum of the contact forces on `body` (N), from the contacts of a state (each pair once).
Eigen::Vector3d body_contact_force(const World& world, const std::vector<ContactRecord>& contacts,
                                   std::uint32_t body);

// One servo update, as servo.csv writes it.
struct ServoSample {
  double time = 0;      // s
  double target = 0;    // Pa
  double measured = 0;  // Pa
  double position = 0;  // m, the prop's centre of mass along direction
  double speed = 0;     // m/s along direction, as set for the next `every` steps
};

// The servos of a run's props: updates them where due and keeps their samples for servo.csv.
class ServoControl {
 public:
  // `servos[k]` drives body `bodies[k]`.
  ServoControl(std::vector<Servo> servos, std::vector<std::uint32_t> bodies);
  bool empty() const { return servos_.empty(); }
  // Steps from `step` to the next update of any servo (at least 1; a large number when there is none).
  std::int64_t steps_to_next(std::int64_t step) const;
  // At a step where some servo is due: measures its stress on `world`'s contacts, sets its body's
  // velocity in `world` and records the sample. True when a velocity was set (reload the stepper).
  bool update(World& world, Stepper& stepper, std::int64_t step);
  const std::vector<std::vector<ServoSample>>& samples() const { return samples_; }
  // servo.csv: one row per update, "servo" being the prop's index among the servoed props.
  std::string csv() const;
  std::int64_t rows() const;  // servo.csv's rows, header apart

 private:
  std::vector<Servo> servos_;
  std::vector<std::uint32_t> bodies_;
  std::vector<std::vector<ServoSample>> samples_;
};

}  // namespace ts::scene
