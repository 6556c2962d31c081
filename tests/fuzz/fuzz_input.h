#pragma once
// What every fuzz target shares: the input written to a file (the readers take paths), and the
// rule that a reader may only refuse input with an InputError - any other exception escapes and
// libFuzzer reports it as a crash, as it does ASan's and UBSan's findings.
#include <unistd.h>

#include <cstdint>
#include <fstream>
#include <string>

#include "trimbot/common/input_error.h"

namespace trimbot::fuzz {

inline std::string WriteInput(const std::uint8_t* data, std::size_t size, const std::string& extension) {
  static const std::string path = "/tmp/trimbot_fuzz_" + std::to_string(getpid()) + extension;
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path;
}

template <typename Read>
void ExpectOnlyInputErrors(Read read) {
  try {
    read();
  } catch (const InputError&) {
    // refused with a message naming the file: the expected outcome for most inputs
  }
}

}  // namespace trimbot::fuzz
