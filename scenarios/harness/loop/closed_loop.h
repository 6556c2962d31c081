#pragma once
// The one loop that steps the simulated robot and its pilot together, for every command
// (run, drive, fusion, bench). Per physics step:
//   simulator.Step -> sensor messages + ground truth
//   [test fixture: simulated pose fixes from ground truth]
//   pilot: sensor messages (and fixes) in -> commands out -> simulator
//   observers: see the step (sensors, ground truth, commands, the stack's telemetry)
// Ground truth goes to the fixture and the observers, never to the pilot.
#include <cmath>
#include <functional>
#include <vector>

#include "trimbot/messages/commands.h"
#include "trimbot/messages/sensor_messages.h"
#include "trimbot/sim/simulator.h"
#include "trimbot/stack/robot_stack.h"

namespace trimbot::scenarios {

class SimulatedPoseFixes;

// One step of the loop as the observers see it.
struct StepView {
  double time = 0.0;
  double timestep = 0.0;
  const sim::SensorOutputs& sensors;
  const std::vector<messages::PoseFix>& pose_fixes;  // delivered to the pilot this step
  const sim::GroundTruth& truth;
  const messages::RobotCommands& commands;
  const stack::Telemetry* telemetry;  // null when no robot software runs
};

// What commands the robot in the loop (its pilot): the robot software, or an open-loop player.
// (The sim's BaseController and ArmController are the motor controllers of the plant.)
class Pilot {
 public:
  virtual ~Pilot() = default;
  // The step's sensor messages (and pose fixes from an external source) in, commands out.
  virtual messages::RobotCommands Step(double time, const sim::SensorOutputs& sensors,
                                       const std::vector<messages::PoseFix>& pose_fixes) = 0;
  // What of a ring frame exposed at `time` it would use (for on-demand rendering; empty: none).
  virtual messages::RingRequest RingRequestAt(double /*time*/) const { return {}; }
  // The mission is over (done or given up).
  virtual bool Finished() const = 0;
  virtual const stack::Telemetry* telemetry() const { return nullptr; }
};

class Observer {
 public:
  virtual ~Observer() = default;
  virtual void Observe(const StepView& step) = 0;
};

// For an observer sampling at `rate` Hz: the next sample time after a sample at `t`, on the grid
// k / rate (where the trial's TUM files sample too), robust to the steps' rounding. Sample when
// step.time + 1e-9 >= it.
inline double NextSampleTime(double t, double rate) { return (std::floor(t * rate + 1e-6) + 1.0) / rate; }

struct LoopOptions {
  double time_limit = 0.0;  // s of simulated time
  // The simulator renders only the cameras the pilot asks for, when it asks (it must have
  // been configured with render_cameras and without cameras_on_schedule).
  bool render_on_demand = false;
  // Whether an offline consumer beside the pilot (e.g. the map builder) wants the whole ring
  // exposed in this step, at the simulator's configured resolution; merged with the pilot's.
  std::function<bool(const sim::GroundTruth&)> ring_demand;
  SimulatedPoseFixes* pose_fixes = nullptr;  // test fixture, when the stack is configured for it
  std::function<void(double)> progress;      // called about once per simulated second
};

// Steps until the pilot has finished or the time limit; returns whether it finished.
bool RunClosedLoop(sim::Simulator& simulator, Pilot& pilot, const std::vector<Observer*>& observers,
                   const LoopOptions& options);

}  // namespace trimbot::scenarios
