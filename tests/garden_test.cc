// Gardens as data: loading, textures, and bad garden files.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "test_support.h"
#include "trimbot/common/input_error.h"
#include "trimbot/garden/garden.h"
#include "trimbot/garden/textures.h"

namespace trimbot::garden {
namespace {

using testing::SourcePath;
using testing::WriteTempFile;

TEST(Garden, TestLawnLoadsEveryObject) {
  const Garden garden = Garden::Load(SourcePath("garden_scenes/gardens/test_lawn.yaml"));
  EXPECT_EQ(garden.name, "test_lawn");
  ASSERT_EQ(garden.objects.size(), 9u);
  EXPECT_EQ(garden.objects[4].object_class, ObjectClass::kHedge);
  EXPECT_DOUBLE_EQ(garden.objects[4].position.x(), 8.5);
  EXPECT_NEAR(garden.objects[3].yaw, M_PI / 6, 1e-12);
  EXPECT_EQ(garden.ground, Surface::kGrass);
}

TEST(Garden, ResolvesNamesAndRejectsUnknownOnes) {
  const std::string dir = SourcePath("garden_scenes/gardens");
  EXPECT_EQ(Garden::Resolve("test_lawn", dir), dir + "/test_lawn.yaml");
  try {
    Garden::Resolve("atlantis", dir);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("unknown garden 'atlantis' (known: "), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("test_lawn"), std::string::npos);
  }
}

void ExpectGardenError(const std::string& name, const std::string& contents, const std::string& problem) {
  const std::string path = WriteTempFile(name, contents);
  try {
    Garden::Load(path);
    FAIL() << "expected an error about " << problem;
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), path);
    EXPECT_NE(std::string(e.what()).find(problem), std::string::npos) << e.what();
  }
}

TEST(Garden, BadFilesNameTheFileLineAndKey) {
  const std::string head = "name: g\nsize: [10, 10]\nground: grass\n";
  ExpectGardenError("unknown_class.yaml",
                    head + "objects:\n  - {id: 1, class: bush, shape: box, size: [1, 1, 1], position: [0, 0]}\n",
                    "line 5: key 'objects[0].class': unknown object class 'bush'");
  ExpectGardenError("unknown_key.yaml",
                    head + "objects:\n  - {id: 1, class: rose, shape: box, size: [1, 1, 1], position: [0, 0], colour: red}\n",
                    "unknown key 'objects[0].colour'");
  ExpectGardenError("duplicate.yaml",
                    head + "objects:\n  - {id: 1, class: rose, shape: box, size: [1, 1, 1], position: [0, 0]}\n"
                           "  - {id: 1, class: rose, shape: box, size: [1, 1, 1], position: [2, 0]}\n",
                    "duplicate id 1");
  ExpectGardenError("negative.yaml",
                    head + "objects:\n  - {id: 1, class: rose, shape: box, size: [1, -1, 1], position: [0, 0]}\n",
                    "all extents must be positive");
  ExpectGardenError("surface.yaml", "name: g\nsize: [10, 10]\nground: lava\nobjects: []\n", "unknown surface 'lava'");
  ExpectGardenError("no_objects.yaml", head, "key 'objects': missing");
  ExpectGardenError("not_yaml.yaml", "name: [g\n", "malformed YAML");
}

TEST(Textures, SameSeedSameImageOtherSeedOther) {
  const cv::Mat a = MakeTexture(Material::kGrass, 5, 128);
  const cv::Mat b = MakeTexture(Material::kGrass, 5, 128);
  const cv::Mat c = MakeTexture(Material::kGrass, 6, 128);
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(a, c, cv::NORM_L1), 0.0);
  // Texture detail: neighbouring pixels differ (the cameras need structure to match).
  cv::Mat grey;
  cv::Scalar mean, stddev;
  cv::meanStdDev(a, mean, stddev);
  EXPECT_GT(stddev[1], 10.0);
}

}  // namespace
}  // namespace trimbot::garden
