#include "runners/fusion_drive.h"

#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>

#include "evaluation/fusion_evaluator.h"
#include "loop/closed_loop.h"
#include "loop/drive_plan.h"
#include "loop/pilots.h"
#include "loop/setting.h"
#include "trimbot/common/atomic_file.h"
#include "trimbot/garden/garden.h"
#include "trimbot/sim/simulator.h"
#include "trimbot/stack/robot_stack.h"

namespace trimbot::scenarios {
namespace {

// Prints each registration as the evaluator scores it.
class PairPrinter : public Observer {
 public:
  explicit PairPrinter(const FusionEvaluator& evaluator) : evaluator_(evaluator) {}
  void Observe(const StepView&) override {
    const auto& pairs = evaluator_.pairs();
    for (; printed_ < pairs.size(); ++printed_) {
      const FusionPairError& e = pairs[printed_];
      std::cout << std::fixed << std::setw(5) << printed_ + 1 << std::setw(9) << e.previous_points << "/" << std::left
                << std::setw(8) << e.points << std::right << std::setprecision(2) << std::setw(19)
                << e.odometry_translation_cm << std::setw(10) << e.odometry_rotation_deg << std::setw(22)
                << e.dugma_translation_cm << std::setw(10) << e.dugma_rotation_deg << std::setprecision(3)
                << std::setw(11) << e.seconds << "\n";
    }
  }

 private:
  const FusionEvaluator& evaluator_;
  std::size_t printed_ = 0;
};

}  // namespace

int RunFusionDrive(const FusionDriveOptions& options, const ProjectPaths& paths) {
  // The inputs are read and checked before the output folder is touched.
  const DrivePlan plan = DrivePlan::Load(options.plan);
  sim::SimulatorConfig config =
      MakeSimulatorConfig(paths, plan.setting, LoadGarden(plan.setting, paths), options.out + "/world");
  stack::StackParameters parameters = stack::StackParameters::Load(paths.robot_files().stack_parameters);
  std::filesystem::create_directories(options.out);
  config.cameras_on_schedule = false;  // only the frames the stack's local fusion wants are rendered
  sim::Simulator simulator(config);

  // The stack listens with local fusion on; the plan drives.
  parameters.local_fusion = options.fusion;
  stack::RobotStack listener(paths.robot_files(), parameters, config.seed);
  listener.SetInitialPose(0.0, plan.setting.start);
  // Enough drive for the clouds asked for (one more frame than registrations), within the plan.
  const double duration = std::min(plan.duration(), options.fusion.interval * options.clouds + 0.5);
  DrivePlanPlayer player(plan, duration, &listener);
  FusionEvaluator evaluator;
  PairPrinter printer(evaluator);
  LoopOptions loop;
  loop.time_limit = duration;
  loop.render_on_demand = true;
  std::cout << " pair  points(prev/cur)  odometry: trans (cm) rot (deg)   DUGMA: trans (cm) rot (deg)   time (s)\n";
  RunClosedLoop(simulator, player, {&evaluator, &printer}, loop);

  nlohmann::json summary = evaluator.ToJson();
  const nlohmann::json& mean = summary["mean"];
  std::cout << std::fixed << std::setprecision(2) << "mean over " << evaluator.pairs().size() << " pairs: odometry "
            << mean["odometry_translation_cm"].get<double>() << " cm / " << mean["odometry_rotation_deg"].get<double>()
            << " deg -> DUGMA " << mean["dugma_translation_cm"].get<double>() << " cm / "
            << mean["dugma_rotation_deg"].get<double>() << " deg, " << std::setprecision(3)
            << mean["seconds"].get<double>() << " s per registration\n";
  summary["plan"] = options.plan;
  summary["interval_s"] = options.fusion.interval;
  WriteFileAtomically(options.out + "/fusion.json", summary.dump(2));
  return 0;
}

}  // namespace trimbot::scenarios
