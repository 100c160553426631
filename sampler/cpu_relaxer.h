#pragma once
// The repulsion sampler's relaxation on the CPU (sampler/relaxer.h): exactly the algorithm of
// shaders/sampler/relax.comp, project.comp and reduce_steps.comp, on the host copy of the same sparse
// NanoVDB field (sdf::HostField: the same trilinear values and central-difference gradient), with
// TBB over the particles. Each step is a Jacobi update, as on the GPU: every particle reads the
// positions of the step before, so the result does not depend on the order or the threads.
//
// Arithmetic: the particles' positions and momentum steps are kept in double between steps, and every
// sum is taken in double. The interface's positions are float (what the GPU holds), but the
// convergence test compares the mean step with tolerance * spacing, which at 10^6 particles on a
// 15 cm mesh is only ~7 float ulps of a coordinate; in double the steps are never quantised, so the
// CPU path converges at least as well as the GPU path. Each particle's sums run in a fixed order (the
// grid's), so the result does not depend on the thread count either.
//
// Why it exists: on a software GL device (Mesa llvmpipe) every dispatch has a fixed cost that small
// counts do not amortise (7 dispatches a step), and llvmpipe caps one storage block at 128 MiB, which
// stops the sparse field of a 10^6-particle body. Here nothing is uploaded and no GL context is needed.
#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "sampler/relaxer.h"
#include "sdf/host_field.h"

namespace ts::sampler {

class CpuRelaxer final : public ParticleRelaxer {
 public:
  explicit CpuRelaxer(sdf::HostField field);

  // Wall time of the relaxation's parts over every relax() so far: the neighbour grid's rebuilds, the
  // steps, the convergence checks (with band removals) and the final projection.
  std::string timing_report() override;
  // The GPU relaxer's three phases, with their iterations and checks counted and no round trip.
  std::vector<gpu::HostSyncPhase> round_trips() const override;
  const sdf::HostField& field() const { return field_; }

 private:
  struct State;
  struct Parameters;
  class NeighbourGrid;
  struct StepSums {
    double moved = 0.0, outside = 0.0, moving = 0.0;
  };

  RelaxStats run(std::vector<Eigen::Vector3f>& positions, const RelaxSettings& settings,
                 const RelaxProgress& progress, std::vector<std::uint8_t>* mobile) override;
  static State load(const std::vector<Eigen::Vector3f>& positions, const std::vector<std::uint8_t>* mobile,
                    double cell);
  static void store(const State& state, std::vector<Eigen::Vector3f>& positions,
                    std::vector<std::uint8_t>* mobile);
  Eigen::Vector3d repulsion(const State& state, const NeighbourGrid& grid, std::size_t i,
                            const Parameters& parameters) const;
  void move_particle(State& state, const NeighbourGrid& grid, std::size_t i, const Parameters& parameters,
                     sdf::FieldAccessor& accessor) const;
  void step(State& state, const Parameters& parameters, NeighbourGrid& grid);
  StepSums check(const State& state) const;
  void project(State& state, int steps) const;

  sdf::HostField field_;
  std::int64_t iterations_run_ = 0, checks_run_ = 0;
  double grid_seconds_ = 0.0, step_seconds_ = 0.0, check_seconds_ = 0.0, project_seconds_ = 0.0;
};

}  // namespace ts::sampler
