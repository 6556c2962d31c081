// libFuzzer target: the same bytes as a scenario (with the overrides a user can add on the command
// line) and as a drive plan.
#include "fuzz_input.h"
#include "loop/drive_plan.h"
#include "loop/scenario.h"
#include "trimbot/common/overrides.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace trimbot;
  const std::string path = fuzz::WriteInput(data, size, ".yaml");
  fuzz::ExpectOnlyInputErrors([&] { scenarios::Scenario::Load(path); });
  fuzz::ExpectOnlyInputErrors([&] {
    scenarios::Scenario::Load(path, ParseOverrides({"trials=3", "stack.navigation.follower.lookahead=0.5"}));
  });
  fuzz::ExpectOnlyInputErrors([&] { scenarios::DrivePlan::Load(path); });
  return 0;
}
