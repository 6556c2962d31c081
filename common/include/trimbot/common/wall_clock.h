#pragma once
// Wall-clock spans for timing reports (never for results: those run on simulated time).
#include <chrono>

namespace trimbot {

inline double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace trimbot
