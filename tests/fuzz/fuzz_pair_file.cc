// libFuzzer target: the registration pair file reader.
#include "evaluation/registration_pair_file.h"
#include "fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace trimbot;
  const std::string path = fuzz::WriteInput(data, size, ".txt");
  fuzz::ExpectOnlyInputErrors([&] { scenarios::LoadRegistrationPair(path); });
  return 0;
}
