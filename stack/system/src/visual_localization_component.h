#pragma once
// The stack's own visual localization: a ring frame localized against the visual map now and then,
// its pose fix applied to the EKF once its computation would have finished (the latency: drawn or
// measured, and the localizer works on one frame at a time).
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "ring_component.h"
#include "trimbot/common/random.h"
#include "trimbot/stack/ekf.h"
#include "trimbot/stack/stack_parameters.h"
#include "trimbot/visual_localization/localizer.h"

namespace trimbot::stack {

class VisualLocalizationComponent : public RingComponent {
 public:
  // `seed` seeds the latency draws.
  VisualLocalizationComponent(const StackParameters& parameters, std::uint64_t seed);

  void SetLocalizer(std::unique_ptr<visual_localization::VisualLocalizer> localizer);
  bool has_localizer() const { return localizer_ != nullptr; }

  // Localization is visual, has a map, is idle and its rate allows a frame at `stamp`.
  bool Due(double stamp, const StackState& state) const override;
  messages::RingRequest Request(const StackState& state) const override;
  void Consume(const messages::RingFrame& frame, StackState* state, Telemetry* telemetry) override;

  // Applies the fixes whose computation has finished by `stamp` (telemetry: the fixes applied).
  void DeliverFixes(double stamp, Ekf* ekf, Telemetry* telemetry);
  // Localization is visual and the estimate's position is too uncertain to drive on.
  bool Lost(const Ekf& ekf) const;
  // The frames localized since the last call, and what came of each.
  std::vector<LocalizationAttempt> TakeAttempts() { return std::exchange(attempts_, {}); }

 private:
  struct PendingFix {
    double ready = 0.0;
    messages::PoseFix fix;
  };

  const StackParameters& parameters_;
  std::unique_ptr<visual_localization::VisualLocalizer> localizer_;
  Rng latency_rng_;
  std::vector<PendingFix> pending_fixes_;  // still "being computed"
  std::vector<LocalizationAttempt> attempts_;
  double busy_until_ = -1.0;
  double next_frame_ = 0.0;
};

}  // namespace trimbot::stack
