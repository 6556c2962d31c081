// Gardens as data: loading, textures, and bad garden files.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "test_support.h"
#include "trimbot/common/input_error.h"
#include "trimbot/garden/conditions.h"
#include "trimbot/garden/garden.h"
#include "trimbot/garden/garden_tools.h"
#include "trimbot/garden/object_mesh.h"
#include "trimbot/garden/textures.h"

#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

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
  ExpectGardenError(
      "unknown_key.yaml",
      head + "objects:\n  - {id: 1, class: rose, shape: box, size: [1, 1, 1], position: [0, 0], colour: red}\n",
      "unknown key 'objects[0].colour'");
  ExpectGardenError("duplicate.yaml",
                    head +
                        "objects:\n  - {id: 1, class: rose, shape: box, size: [1, 1, 1], position: [0, 0]}\n"
                        "  - {id: 1, class: rose, shape: box, size: [1, 1, 1], position: [2, 0]}\n",
                    "duplicate id 1");
  ExpectGardenError("negative.yaml",
                    head + "objects:\n  - {id: 1, class: rose, shape: box, size: [1, -1, 1], position: [0, 0]}\n",
                    "objects[0].size': each must be in [0.001, 200] m");
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

// Ground variants: the base tile's texels along the border (any arrangement of variants is
// seamless), different inside (the lawn does not repeat every tile).
TEST(Textures, GroundVariantsShareTheBaseBorderAndDifferInside) {
  const cv::Mat base = MakeTexture(Material::kGrass, 5, 128);
  const cv::Rect border_band(0, 0, 128, 8), inside(40, 40, 48, 48);
  const std::vector<cv::Mat> variants = MakeGroundVariants(Material::kGrass, 5, 128);
  ASSERT_EQ(variants.size(), static_cast<std::size_t>(kGroundVariants));
  for (int k = 0; k < kGroundVariants; ++k) {
    const cv::Mat& variant = variants[static_cast<std::size_t>(k)];
    ASSERT_EQ(variant.size(), base.size());
    EXPECT_EQ(cv::norm(variant(border_band), base(border_band), cv::NORM_INF), 0.0) << "variant " << k;
    cv::Mat difference;
    cv::absdiff(variant(inside), base(inside), difference);
    EXPECT_GT(cv::mean(difference)[1], 5.0) << "variant " << k << " differs from the base inside";
  }
  EXPECT_THROW(MakeGroundVariants(Material::kBark, 5, 64), std::invalid_argument);
}

// The lawn's patches cover the area, each showing one whole variant (texture coordinates 0..1, so
// neighbours meet on the shared border texels), all variants used, columns mirrored and not.
TEST(LawnMesh, PatchesShowWholeVariantsMixedAndCoverTheArea) {
  const Eigen::Vector2d min(-20.0, -18.0);
  const std::vector<Mesh> meshes = LawnMeshes(min, {20.0, 18.0}, 4.0, 3);  // 10 x 9 patches
  ASSERT_EQ(meshes.size(), static_cast<std::size_t>(kGroundVariants));
  struct Patch {
    double u_min = 1e9, u_max = -1e9, v_min = 1e9, v_max = -1e9, u_at_x_min = 0.0, x_min = 1e9;
    int faces = 0;
  };
  double top_area = 0.0;
  int patches_total = 0, mirrored = 0;
  for (const Mesh& mesh : meshes) {
    std::map<std::pair<int, int>, Patch> patches;
    for (const auto& face : mesh.faces) {
      const Eigen::Vector3d& a = mesh.vertices[static_cast<std::size_t>(face[0])];
      const Eigen::Vector3d& b = mesh.vertices[static_cast<std::size_t>(face[1])];
      const Eigen::Vector3d& c = mesh.vertices[static_cast<std::size_t>(face[2])];
      const Eigen::Vector3d normal = (b - a).cross(c - a);
      if (normal.z() <= 0.0 || a.z() != 0.0) continue;  // the tops only
      top_area += 0.5 * normal.z();
      const Eigen::Vector3d centroid = (a + b + c) / 3.0;
      Patch& patch = patches[{static_cast<int>(std::floor((centroid.x() - min.x()) / 4.0)),
                              static_cast<int>(std::floor((centroid.y() - min.y()) / 4.0))}];
      ++patch.faces;
      for (const int v : face) {
        const Eigen::Vector2d uv = mesh.texcoords[static_cast<std::size_t>(v)];
        const Eigen::Vector3d& p = mesh.vertices[static_cast<std::size_t>(v)];
        patch.u_min = std::min(patch.u_min, uv.x());
        patch.u_max = std::max(patch.u_max, uv.x());
        patch.v_min = std::min(patch.v_min, uv.y());
        patch.v_max = std::max(patch.v_max, uv.y());
        if (p.x() < patch.x_min) {
          patch.x_min = p.x();
          patch.u_at_x_min = uv.x();
        }
      }
    }
    EXPECT_FALSE(patches.empty()) << "every variant is used";
    for (const auto& [index, patch] : patches) {
      EXPECT_EQ(patch.u_min, 0.0);
      EXPECT_EQ(patch.u_max, 1.0);
      EXPECT_EQ(patch.v_min, 0.0);
      EXPECT_EQ(patch.v_max, 1.0);
      mirrored += patch.u_at_x_min > 0.5 ? 1 : 0;
    }
    patches_total += static_cast<int>(patches.size());
  }
  EXPECT_NEAR(top_area, 40.0 * 36.0, 1e-9);
  EXPECT_EQ(patches_total, 90);
  EXPECT_GT(mirrored, 0);
  EXPECT_LT(mirrored, 90);
}

// The Wageningen garden against its source map, read here independently of the importer.
TEST(WageningenGarden, HasEveryObjectOfTheMapInItsPlace) {
  const Garden garden = Garden::Load(SourcePath("garden_scenes/gardens/wageningen.yaml"));
  std::map<int, const GardenObject*> by_id;
  for (const auto& object : garden.objects) by_id[object.id] = &object;
  std::ifstream csv(SourcePath("garden_scenes/data/wur31_objects.csv"));
  std::string line;
  int rows = 0;
  const std::map<std::string, ObjectClass> classes = {
      {"Hedge-Ivy", ObjectClass::kHedge},         {"Hedge-Box", ObjectClass::kHedge},
      {"Topiary-Generic", ObjectClass::kTopiary}, {"Topiary-Ellipsoid", ObjectClass::kTopiary},
      {"Rose-Generic", ObjectClass::kRose},       {"Obstacle-Tree", ObjectClass::kTree},
      {"Obstacle-Trunk", ObjectClass::kTrunk},    {"Obstacle-Fence", ObjectClass::kFence},
      {"Obstacle-Post", ObjectClass::kFence},     {"Obstacle-Generic", ObjectClass::kObstacle},
      {"Robot-Vehicle", ObjectClass::kObstacle},  {"Background-Generic", ObjectClass::kObstacle}};
  while (std::getline(csv, line)) {
    if (line.empty() || line[0] == '#' || line.rfind("id,", 0) == 0) continue;
    std::stringstream row(line);
    std::vector<std::string> f;
    for (std::string field; std::getline(row, field, ',');) f.push_back(field);
    ASSERT_EQ(f.size(), 10u) << line;
    ++rows;
    const int id = std::stoi(f[0]);
    ASSERT_TRUE(by_id.count(id)) << "object " << id << " (" << f[1] << ") missing";
    const GardenObject& object = *by_id[id];
    ASSERT_TRUE(classes.count(f[1])) << f[1];
    EXPECT_EQ(object.object_class, classes.at(f[1])) << id;
    EXPECT_NEAR(object.position.x(), std::stod(f[6]), 1e-6) << id;
    EXPECT_NEAR(object.position.y(), std::stod(f[7]), 1e-6) << id;
    EXPECT_NEAR(object.size.x(), std::stod(f[3]), 1e-6) << id;
    EXPECT_NEAR(object.size.y(), std::stod(f[4]), 1e-6) << id;
    EXPECT_NEAR(object.yaw, std::stod(f[9]) * M_PI / 180.0, 1e-9) << id;
    // Tops stay where the map has them (ground at z = -1.48); low objects stand on the ground.
    const double top = std::stod(f[8]) + 1.48 + std::stod(f[5]);
    EXPECT_NEAR(object.base_height + object.size.z(), top, 1e-6) << id;
    EXPECT_TRUE(object.base_height == 0.0 || object.object_class == ObjectClass::kTree) << id;
  }
  EXPECT_EQ(rows, 44);
  EXPECT_EQ(garden.objects.size(), 44u);
  EXPECT_EQ(garden.paths.size(), 3u);
  EXPECT_EQ(garden.SurfaceAt({2.0, -1.75}), Surface::kGravel);
  EXPECT_EQ(garden.SurfaceAt({10.7, 0.0}), Surface::kPavement);
  EXPECT_EQ(garden.SurfaceAt({0.0, 1.5}), Surface::kGrass);
}

TEST(GardenGenerator, SameSeedSameGardenOtherSeedAnother) {
  GeneratorParameters parameters;
  parameters.seed = 7;
  const Garden a = GenerateGarden(parameters);
  const Garden b = GenerateGarden(parameters);
  parameters.seed = 8;
  const Garden c = GenerateGarden(parameters);
  EXPECT_EQ(a.ToYaml(), b.ToYaml());
  EXPECT_NE(a.ToYaml(), c.ToYaml());
  // Every requested object is there: 8 topiary, 4 roses, 2 hedges, 2 trees (+ trunks), 2 obstacles, 4 fences.
  std::map<ObjectClass, int> count;
  for (const auto& object : a.objects) ++count[object.object_class];
  EXPECT_EQ(count[ObjectClass::kTopiary], 8);
  EXPECT_EQ(count[ObjectClass::kRose], 4);
  EXPECT_EQ(count[ObjectClass::kHedge], 2);
  EXPECT_EQ(count[ObjectClass::kTree], 2);
  EXPECT_EQ(count[ObjectClass::kTrunk], 2);
  EXPECT_EQ(count[ObjectClass::kObstacle], 2);
  EXPECT_EQ(count[ObjectClass::kFence], 4);
  EXPECT_EQ(a.paths.size(), 2u);
  // The written file loads back to the same garden.
  const Garden reloaded = Garden::Load(WriteTempFile("generated.yaml", a.ToYaml()));
  EXPECT_EQ(reloaded.ToYaml(), a.ToYaml());
}

TEST(GardenGenerator, ShapesTopiaryInTheSharesAskedFor) {
  GeneratorParameters parameters;
  parameters.seed = 11;
  parameters.size = {30.0, 30.0};
  parameters.topiary = 60;
  std::map<Shape, int> count;
  for (const auto& object : GenerateGarden(parameters).objects) {
    if (object.object_class == ObjectClass::kTopiary) ++count[object.shape];
  }
  EXPECT_EQ(count[Shape::kCylinder], 0) << "the default draws boxes and ellipsoids only";
  EXPECT_GT(count[Shape::kBox], 6);
  parameters.topiary_box_share = 0.2;
  parameters.topiary_cylinder_share = 0.5;
  count.clear();
  int topiary = 0;
  for (const auto& object : GenerateGarden(parameters).objects) {
    if (object.object_class != ObjectClass::kTopiary) continue;
    ++topiary;
    ++count[object.shape];
    if (object.shape == Shape::kCylinder) {
      EXPECT_EQ(object.size.x(), object.size.y()) << "a round plan";
    }
  }
  // Binomial: 3 standard deviations round the shares' expectation.
  const auto near = [topiary](int n, double share) {
    return std::abs(n - share * topiary) <= 3.0 * std::sqrt(topiary * share * (1.0 - share));
  };
  EXPECT_GT(topiary, 40);
  EXPECT_TRUE(near(count[Shape::kBox], 0.2)) << count[Shape::kBox] << " of " << topiary;
  EXPECT_TRUE(near(count[Shape::kCylinder], 0.5)) << count[Shape::kCylinder] << " of " << topiary;
}

TEST(GardenGenerator, KeepsRoomForTheRobotBetweenObjects) {
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    GeneratorParameters parameters;
    parameters.seed = seed;
    const Garden garden = GenerateGarden(parameters);
    for (size_t i = 0; i < garden.objects.size(); ++i) {
      for (size_t j = i + 1; j < garden.objects.size(); ++j) {
        const auto& a = garden.objects[i];
        const auto& b = garden.objects[j];
        const bool crown_on_trunk = a.object_class == ObjectClass::kTree || b.object_class == ObjectClass::kTree;
        if (crown_on_trunk || a.object_class == ObjectClass::kFence || b.object_class == ObjectClass::kFence) continue;
        // Footprints at least `clearance` apart imply centres at least the two smallest half
        // extents plus the clearance apart.
        EXPECT_GE((a.position - b.position).norm(),
                  a.size.head<2>().minCoeff() / 2 + b.size.head<2>().minCoeff() / 2 + parameters.robot_clearance - 1e-9)
            << "seed " << seed << ": objects " << a.id << " and " << b.id;
      }
    }
  }
}

TEST(OccupancyMap, MarksEveryFootprintBelowTheClearance) {
  const Garden garden = Garden::Load(SourcePath("garden_scenes/gardens/wageningen.yaml"));
  const double clearance = 1.0;
  const OccupancyMap map = MakeOccupancyMap(garden, 0.05, clearance);
  int marked = 0;
  for (const auto& object : garden.objects) {
    const cv::Point cell = map.Cell(object.position);
    ASSERT_TRUE(cell.inside(cv::Rect(0, 0, map.occupied.cols, map.occupied.rows))) << object.id;
    if (object.base_height < clearance) {
      EXPECT_EQ(map.occupied.at<uchar>(cell), 255) << "object " << object.id << " not marked";
      ++marked;
    }
  }
  EXPECT_EQ(marked, 41);  // 44 objects less the three tree crowns (their trunks are marked)
  // The whole footprint: every cell whose centre lies in one is occupied.
  double footprint_area = 0.0;
  for (const auto& object : garden.objects) {
    const double scale = FootprintScaleBelow(object, clearance);
    const double box_area = scale * scale * object.size.x() * object.size.y();
    footprint_area += object.shape == Shape::kBox ? box_area : M_PI / 4 * box_area;
  }
  for (int row = 0; row < map.occupied.rows; ++row) {
    for (int column = 0; column < map.occupied.cols; ++column) {
      if (ObjectAt(garden, map.CellCentre({column, row}), clearance) != nullptr) {
        ASSERT_EQ(map.occupied.at<uchar>(row, column), 255) << "cell " << column << ", " << row;
      }
    }
  }
  // ...and no more on average: marking every cell a footprint touches would grow each object by
  // half a cell all round (some 2 m2 here); the map's area stays within 2 % of the footprints'.
  const double occupied_area = cv::countNonZero(map.occupied) * map.resolution * map.resolution;
  EXPECT_NEAR(occupied_area, footprint_area, 0.02 * footprint_area);
  // Open lawn is free: between the roses, and in the middle of the garden's west part.
  EXPECT_EQ(map.occupied.at<uchar>(map.Cell({0.3, 1.4})), 0);
  EXPECT_EQ(map.occupied.at<uchar>(map.Cell({-1.5, -1.5})), 0);
  const double occupied_fraction = cv::countNonZero(map.occupied) / static_cast<double>(map.occupied.total());
  EXPECT_GT(occupied_fraction, 0.03);
  EXPECT_LT(occupied_fraction, 0.25);
}

TEST(FoliageMesh, TrimmedIsTheTargetShapeAndGrowthAddsIrregularly) {
  GardenObject bush;
  bush.id = 3;
  bush.object_class = ObjectClass::kTopiary;
  bush.shape = Shape::kEllipsoid;
  bush.size = {0.8, 0.8, 0.8};
  auto radii = [&](double growth) {
    std::vector<double> r;
    for (const auto& v : ObjectMesh(bush, 1, growth).vertices) r.push_back((v - Eigen::Vector3d(0, 0, 0.4)).norm());
    return r;
  };
  const auto trimmed = radii(0.0);
  const auto grown = radii(1.0);
  double max_deviation = 0.0, mean_growth = 0.0, max_growth = 0.0, min_growth = 1.0;
  for (size_t i = 0; i < trimmed.size(); ++i) {
    max_deviation = std::max(max_deviation, std::abs(trimmed[i] - 0.4));
    mean_growth += (grown[i] - trimmed[i]) / trimmed.size();
    max_growth = std::max(max_growth, grown[i] - trimmed[i]);
    min_growth = std::min(min_growth, grown[i] - trimmed[i]);
  }
  EXPECT_LT(max_deviation, 0.03);   // leaf clumps only: within 3 cm of the trimmed sphere
  EXPECT_GT(max_deviation, 0.005);  // ... but not a smooth primitive
  EXPECT_GT(mean_growth, 0.05);     // a season adds several cm on average
  EXPECT_LE(max_growth, kMaxGrowth * 1.6 + 1e-9);
  EXPECT_GT(max_growth - min_growth, 0.05);  // and unevenly (shoots)
}

TEST(Conditions, SunFollowsTheDayAtWageningen) {
  Garden garden;  // latitude 52 N, north along +y
  Conditions noon;
  noon.time_of_day = 12.0;
  noon.day_of_year = 172;  // midsummer: 90 - 52 + 23.4 = 61.4 degrees
  Sun sun = SunFor(garden, noon);
  EXPECT_NEAR(sun.elevation * 180 / M_PI, 61.4, 0.5);
  EXPECT_NEAR(std::remainder(sun.azimuth + M_PI / 2, 2 * M_PI), 0.0, 0.01);  // from the south (-y)
  Conditions evening = noon;
  evening.time_of_day = 18.0;
  sun = SunFor(garden, evening);
  EXPECT_LT(sun.elevation * 180 / M_PI, 30.0);
  EXPECT_LT(std::cos(sun.azimuth), -0.3);  // from the west, which is -x when north is +y
}

}  // namespace
}  // namespace trimbot::garden
