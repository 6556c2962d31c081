#include "evaluation/registration_pair_file.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <set>
#include <sstream>

#include "trimbot/common/atomic_file.h"
#include "trimbot/common/input_error.h"
#include "trimbot/common/parse_number.h"

namespace trimbot::scenarios {
namespace {

namespace fs = std::filesystem;

// Reads a pair file line by line, every error naming the file and the line.
class PairReader {
 public:
  explicit PairReader(std::string path) : path_(std::move(path)) {}

  RegistrationPair Read() {
    std::ifstream in(path_);
    if (!in) throw InputError(path_, "cannot open the pair file");
    pair_.name = fs::path(path_).stem().string();
    std::string line;
    while (std::getline(in, line)) {
      ++line_;
      const auto hash = line.find('#');
      if (hash != std::string::npos) line.resize(hash);
      std::istringstream fields(line);
      std::string head;
      if (!(fields >> head)) continue;
      if (remaining_ > 0) {
        PointLine(line);
      } else {
        if (!seen_.insert(head).second) Fail("'" + head + "' appears twice");
        HeaderLine(head, fields);
      }
    }
    if (remaining_ > 0) throw InputError(path_, "ends " + std::to_string(remaining_) + " points early");
    if (!seen_.count("R") || !seen_.count("t")) throw InputError(path_, "has no ground truth (lines R and t)");
    if (pair_.x.empty() || pair_.y.empty()) throw InputError(path_, "needs both an X and a Y block");
    return std::move(pair_);
  }

 private:
  [[noreturn]] void Fail(const std::string& problem) const {
    throw InputError(path_, "line " + std::to_string(line_) + ": " + problem);
  }

  // The whole token must be the number; points may be NaN (the data set marks unusable ones so),
  // the truth may not.
  double Number(std::istringstream& fields, const std::string& what, bool allow_nan) const {
    std::string token;
    if (!(fields >> token)) Fail("expected " + what);
    if (allow_nan && (token == "nan" || token == "NaN" || token == "-nan")) return std::nan("");
    const auto value = ParseFiniteNumber(token);
    if (!value) Fail("'" + token + "' is not a finite number (" + what + ")");
    return *value;
  }

  void PointLine(const std::string& line) {
    std::istringstream values(line);
    double v[9];
    for (double& value : v) value = Number(values, "9 numbers (x y z c00 c01 c02 c11 c12 c22)", true);
    std::string extra;
    if (values >> extra) Fail("more than 9 numbers on a point line");
    Eigen::Matrix3d c;
    c << v[3], v[4], v[5], v[4], v[6], v[7], v[5], v[7], v[8];
    block_->Add({v[0], v[1], v[2]}, c);
    --remaining_;
  }

  void HeaderLine(const std::string& head, std::istringstream& fields) {
    if (head == "R") {
      Eigen::Matrix3d R;
      for (int i = 0; i < 9; ++i) R(i / 3, i % 3) = Number(fields, "'R' with 9 numbers", false);
      // A matrix that is no rotation would be scored by the clamp in the rotation error as a pass.
      if ((R * R.transpose() - Eigen::Matrix3d::Identity()).norm() > 1e-4 || R.determinant() < 0.0) {
        Fail("'R' is not a rotation (orthonormal with determinant +1)");
      }
      pair_.truth.linear() = R;
    } else if (head == "t") {
      for (int i = 0; i < 3; ++i) pair_.truth.translation()[i] = Number(fields, "'t' with 3 numbers", false);
      if (pair_.truth.translation().norm() > 1e4) Fail("'t' is beyond 10 km");
    } else if (head == "covariances") {
      std::string kind;
      if (!(fields >> kind) || (kind != "metric" && kind != "relative")) {
        Fail("'covariances' is followed by metric (m^2) or relative (weights)");
      }
      pair_.relative_covariances = kind == "relative";
    } else if (head == "X" || head == "Y") {
      std::string count;
      fields >> count;
      const auto points = ParseInteger(count, 1, 10000000);
      if (!points) Fail("'" + head + "' needs a point count in [1, 10000000], got '" + count + "'");
      remaining_ = static_cast<long>(*points);
      block_ = head == "X" ? &pair_.x : &pair_.y;
    } else {
      Fail("unexpected '" + head + "' (expected covariances, R, t, X or Y)");
    }
  }

  std::string path_;
  RegistrationPair pair_;
  std::set<std::string> seen_;  // each of R, t, X, Y, covariances once
  int line_ = 0;
  perception::PointCloud* block_ = nullptr;
  long remaining_ = 0;
};

}  // namespace

RegistrationPair LoadRegistrationPair(const std::string& path) { return PairReader(path).Read(); }

void WriteRegistrationPair(const std::string& path, const RegistrationPair& pair) {
  std::ostringstream out;
  out << std::setprecision(9) << "# rendered by trimbot register-set: x = R y + t\n"
      << (pair.relative_covariances ? "covariances relative\n" : "covariances metric\n");
  const Eigen::Matrix3d& R = pair.truth.linear();
  out << "R " << R(0, 0) << ' ' << R(0, 1) << ' ' << R(0, 2) << ' ' << R(1, 0) << ' ' << R(1, 1) << ' ' << R(1, 2)
      << ' ' << R(2, 0) << ' ' << R(2, 1) << ' ' << R(2, 2) << '\n';
  out << "t " << pair.truth.translation().x() << ' ' << pair.truth.translation().y() << ' '
      << pair.truth.translation().z() << '\n';
  for (const auto& [label, cloud] : {std::pair{"X", &pair.x}, std::pair{"Y", &pair.y}}) {
    out << label << ' ' << cloud->size() << '\n';
    for (std::size_t i = 0; i < cloud->size(); ++i) {
      const Eigen::Vector3d& p = cloud->points[i];
      const Eigen::Matrix3d& c = cloud->covariances[i];
      out << p.x() << ' ' << p.y() << ' ' << p.z() << ' ' << c(0, 0) << ' ' << c(0, 1) << ' ' << c(0, 2) << ' '
          << c(1, 1) << ' ' << c(1, 2) << ' ' << c(2, 2) << '\n';
    }
  }
  WriteFileAtomically(path, out.str());
}

}  // namespace trimbot::scenarios
