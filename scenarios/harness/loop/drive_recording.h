#pragma once
// A drive as `trimbot drive` recorded it (README, "A drive writes"), read back as the robot's own
// log: its IMU samples, wheel ticks and ring frames with their stamps, and the plan it drove (the
// garden, the stated start, the seed). What `trimbot map build DRIVE_FOLDER` builds a map from; the
// folder's ground truth is not read here (evaluation reads it itself).
#include <optional>
#include <string>
#include <vector>

#include "loop/drive_plan.h"
#include "trimbot/messages/sensor_messages.h"

namespace trimbot::scenarios {

// `dir`/frames/NNNNNN: where a drive folder holds ring frame `index`'s images (RunLog writes them,
// DriveRecording reads them).
std::string RecordedFrameFolder(const std::string& dir, long index);

struct RecordedRingFrame {
  long index = 0;
  double stamp = 0.0;  // s, robot time
  bool saved = false;  // whether frames/NNNNNN/ holds its images
};

class DriveRecording {
 public:
  // Reads plan.yaml, summary.json (the seed the drive ran with), sensors/imu.csv,
  // sensors/wheel_ticks.csv and sensors/ring.csv. InputError naming the file (and the line) for a
  // missing file, a malformed line or stamps that go back in time.
  static DriveRecording Load(const std::string& dir);

  const std::string& dir() const { return dir_; }
  const DrivePlan& plan() const { return plan_; }  // its setting's seed is the drive's
  const std::vector<messages::ImuSample>& imu() const { return imu_; }
  const std::vector<messages::WheelTicks>& wheel_ticks() const { return wheel_ticks_; }
  const std::vector<RecordedRingFrame>& frames() const { return frames_; }

  // The saved images of a frame (cam0.png .. cam{cameras-1}.png) as the ring delivered them (rgb8),
  // or nullopt with `gap` naming the image that is missing or unreadable (a gap in the log).
  // InputError naming the image whose size is not `width` x `height` (a drive rendered at a
  // --resolution-scale the calibration does not have).
  std::optional<messages::RingFrame> LoadFrame(const RecordedRingFrame& frame, int cameras, int width, int height,
                                               std::string* gap) const;

 private:
  std::string dir_;
  DrivePlan plan_;
  std::vector<messages::ImuSample> imu_;
  std::vector<messages::WheelTicks> wheel_ticks_;
  std::vector<RecordedRingFrame> frames_;
};

}  // namespace trimbot::scenarios
