#pragma once
// Contact events of the arm: a pair of geoms touching that did not touch in the step before (MuJoCo
// reports a pair once per contact point; the pair counts once).
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "trimbot/sim/simulator.h"

namespace trimbot::scenarios {

class ContactEvents {
 public:
  // This step's arm contacts in; the events among them (pairs new since the last step, as arm
  // geom and other geom) out.
  std::vector<std::pair<std::string, std::string>> Update(const std::vector<sim::ArmContact>& contacts) {
    std::set<std::pair<std::string, std::string>> touching;
    for (const sim::ArmContact& contact : contacts) touching.insert({contact.arm_geom, contact.other_geom});
    std::vector<std::pair<std::string, std::string>> events;
    for (const auto& pair : touching) {
      if (!touching_.count(pair)) events.push_back(pair);
    }
    touching_ = std::move(touching);
    return events;
  }
  // Nothing touches (the steps between were not watched).
  void Clear() { touching_.clear(); }

 private:
  std::set<std::pair<std::string, std::string>> touching_;
};

}  // namespace trimbot::scenarios
