#include "loop/closed_loop.h"

#include "loop/simulated_pose_fixes.h"

namespace trimbot::scenarios {

bool RunClosedLoop(sim::Simulator& simulator, Pilot& pilot, const std::vector<Observer*>& observers,
                   const LoopOptions& options) {
  sim::SensorOutputs sensors;
  sim::GroundTruth truth;
  std::vector<messages::PoseFix> fixes;
  // The pilot's commands for the first step, from no measurements yet.
  simulator.Apply(pilot.Step(simulator.time(), sensors, fixes));
  double next_progress = 1.0;
  while (simulator.time() < options.time_limit - 1e-9) {
    sensors.Clear();
    fixes.clear();
    simulator.Step(&sensors, &truth);
    const double t = simulator.time();
    if (options.render_on_demand && truth.ring_exposed) {
      messages::RingRequest request = pilot.RingRequestAt(t);
      if (options.ring_demand && options.ring_demand(truth)) request = messages::Merge(request, simulator.WholeRing());
      if (!request.empty()) {
        sim::RingCapture capture = simulator.CaptureRing(request, false);
        sensors.ring = std::move(capture.frame);
        truth.ring = std::move(capture.truth);
      }
    }
    if (options.pose_fixes != nullptr) options.pose_fixes->Step(truth, &fixes);

    const messages::RobotCommands commands = pilot.Step(t, sensors, fixes);
    simulator.Apply(commands);
    const StepView view{t, simulator.timestep(), sensors, fixes, truth, commands, pilot.telemetry()};
    for (Observer* observer : observers) observer->Observe(view);

    if (pilot.Finished()) return true;
    if (options.progress && t >= next_progress) {
      options.progress(t);
      next_progress += 1.0;
    }
  }
  return false;
}

}  // namespace trimbot::scenarios
