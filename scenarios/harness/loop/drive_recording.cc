#include "loop/drive_recording.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "trimbot/common/input_error.h"
#include "trimbot/common/parse_number.h"

namespace trimbot::scenarios {
namespace {

// The rows of a CSV file with a header line and `columns` numeric fields a row; each row is passed
// to `row(fields, line_number)`. InputError naming the file and line for a row of the wrong width
// or a field that is not a finite number.
template <typename Row>
void ReadCsv(const std::string& path, std::size_t columns, Row row) {
  std::ifstream file(path);
  if (!file) throw InputError(path, "not found (is this a folder `trimbot drive` wrote?)");
  std::string line;
  std::getline(file, line);  // the header
  std::vector<double> fields;
  for (int number = 2; std::getline(file, line); ++number) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    fields.clear();
    std::istringstream cells(line);
    for (std::string cell; std::getline(cells, cell, ',');) {
      const std::optional<double> value = ParseFiniteNumber(cell);
      if (!value) throw InputError(path, "line " + std::to_string(number) + ": '" + cell + "' is not a finite number");
      fields.push_back(*value);
    }
    if (fields.size() != columns) {
      throw InputError(path, "line " + std::to_string(number) + ": expected " + std::to_string(columns) +
                                 " fields, got " + std::to_string(fields.size()));
    }
    row(fields, number);
  }
}

// Stamps must not go back in time: the stream is replayed in order.
void CheckOrder(const std::string& path, double previous, double stamp, int line) {
  if (stamp < previous) {
    throw InputError(path, "line " + std::to_string(line) + ": stamp " + std::to_string(stamp) +
                               " goes back in time (previous " + std::to_string(previous) + ")");
  }
}

}  // namespace

std::string RecordedFrameFolder(const std::string& dir, long index) {
  std::ostringstream name;
  name << dir << "/frames/" << std::setw(6) << std::setfill('0') << index;
  return name.str();
}

DriveRecording DriveRecording::Load(const std::string& dir) {
  DriveRecording recording;
  recording.dir_ = dir;
  if (!std::filesystem::is_directory(dir)) throw InputError(dir, "not a folder");
  recording.plan_ = DrivePlan::Load(dir + "/plan.yaml");
  const std::string summary_path = dir + "/summary.json";
  std::ifstream summary_file(summary_path);
  if (!summary_file) throw InputError(summary_path, "not found (the drive did not finish?)");
  try {
    recording.plan_.setting.seed = nlohmann::json::parse(summary_file).at("seed").get<std::uint64_t>();
  } catch (const nlohmann::json::exception& e) {
    throw InputError(summary_path, std::string("no seed: ") + e.what());
  }

  const std::string imu_path = dir + "/sensors/imu.csv";
  ReadCsv(imu_path, 7, [&](const std::vector<double>& f, int line) {
    if (!recording.imu_.empty()) CheckOrder(imu_path, recording.imu_.back().stamp, f[0], line);
    messages::ImuSample sample;
    sample.stamp = f[0];
    sample.linear_acceleration = {f[1], f[2], f[3]};
    sample.angular_velocity = {f[4], f[5], f[6]};
    recording.imu_.push_back(sample);
  });
  const std::string ticks_path = dir + "/sensors/wheel_ticks.csv";
  ReadCsv(ticks_path, 3, [&](const std::vector<double>& f, int line) {
    if (!recording.wheel_ticks_.empty()) CheckOrder(ticks_path, recording.wheel_ticks_.back().stamp, f[0], line);
    for (const double count : {f[1], f[2]}) {
      // Encoder counts are whole numbers (and within the 53 bits a double holds exactly).
      if (count != std::floor(count) || std::abs(count) > 9007199254740992.0)
        throw InputError(ticks_path, "line " + std::to_string(line) + ": tick count " + std::to_string(count) +
                                         " is not a whole number");
    }
    recording.wheel_ticks_.push_back({f[0], static_cast<std::int64_t>(f[1]), static_cast<std::int64_t>(f[2])});
  });
  const std::string ring_path = dir + "/sensors/ring.csv";
  ReadCsv(ring_path, 3, [&](const std::vector<double>& f, int line) {
    if (!recording.frames_.empty()) CheckOrder(ring_path, recording.frames_.back().stamp, f[1], line);
    recording.frames_.push_back({static_cast<long>(f[0]), f[1], f[2] != 0.0});
  });
  return recording;
}

std::optional<messages::RingFrame> DriveRecording::LoadFrame(const RecordedRingFrame& frame, int cameras, int width,
                                                             int height, std::string* gap) const {
  messages::RingFrame ring;
  ring.stamp = frame.stamp;
  for (int i = 0; i < cameras; ++i) {
    const std::string path = RecordedFrameFolder(dir_, frame.index) + "/cam" + std::to_string(i) + ".png";
    const cv::Mat bgr = cv::imread(path, cv::IMREAD_COLOR);
    if (bgr.empty()) {
      *gap = path + ": missing or not an image";
      return std::nullopt;
    }
    if (bgr.cols != width || bgr.rows != height) {
      throw InputError(path, "is " + std::to_string(bgr.cols) + "x" + std::to_string(bgr.rows) +
                                 ", the calibration's camera is " + std::to_string(width) + "x" +
                                 std::to_string(height) + " (recorded with --resolution-scale?)");
    }
    cv::Mat rgb;
    cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
    messages::Image image;
    image.stamp = frame.stamp;
    image.camera_index = i;
    image.width = rgb.cols;
    image.height = rgb.rows;
    image.encoding = "rgb8";
    image.data.assign(rgb.data, rgb.data + rgb.total() * rgb.elemSize());
    ring.images.push_back(std::move(image));
  }
  return ring;
}

}  // namespace trimbot::scenarios
