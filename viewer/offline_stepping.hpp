#pragma once
// Stepping a viewed model off line, without a servo loop: through sampled tool trajectories (a
// scene's, or a run's recorded positions), snapshotting at chosen times. What screenshots and the
// replay of a fast model's run use; deterministic, so a picture at time T is reproducible.

#include "formats/trajectory/trajectory.hpp"
#include "viewer/viewed_model.hpp"

#include <functional>
#include <span>
#include <vector>

namespace kerf {

/// Resets `model` and steps it through `trajectories` (one per tool, one rate; a shorter one
/// holds its last state) sample by sample with dt = 1/rate. At each of `times` [s] (ascending)
/// it calls `visit` with a snapshot taken after the last sample at or before that time (a time
/// before the first sample gets the state after the first sample, which is at rest). `on_force`,
/// if given, sees every sample's largest force magnitude [N]. Throws std::invalid_argument on
/// a tool-count or rate mismatch or times out of order.
void step_through(ViewedModel& model, const std::vector<SampledTrajectory>& trajectories, std::span<const double> times,
                  const std::function<void(const ViewFrame&)>& visit, const std::function<void(double)>& on_force = {});

} // namespace kerf
