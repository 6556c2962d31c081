#include "trimbot/garden/textures.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "trimbot/common/random.h"

namespace trimbot::garden {
namespace {

// Blurred white noise with feature size `scale_px`, seamless (wrap-around). Coarse octaves are
// made at low resolution and upsampled: a full-resolution blur with a large sigma costs seconds.
cv::Mat NoiseOctave(cv::RNG& rng, int size, double scale_px) {
  int low = size;
  while (low % 2 == 0 && low >= 16 && scale_px * low / size > 4.0) low /= 2;
  const double sigma = scale_px * low / size;
  cv::Mat noise(low, low, CV_32F);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, 1.0);
  if (sigma > 0.5) {
    const int pad = static_cast<int>(std::ceil(3 * sigma));
    cv::Mat padded;
    cv::copyMakeBorder(noise, padded, pad, pad, pad, pad, cv::BORDER_WRAP);
    cv::GaussianBlur(padded, padded, cv::Size(), sigma);
    noise = padded(cv::Rect(pad, pad, low, low)).clone();
  }
  if (low == size) return noise;
  const int factor = size / low, pad = 2;
  cv::Mat padded, up;
  cv::copyMakeBorder(noise, padded, pad, pad, pad, pad, cv::BORDER_WRAP);
  cv::resize(padded, up, cv::Size(), factor, factor, cv::INTER_CUBIC);
  return up(cv::Rect(pad * factor, pad * factor, size, size)).clone();
}

// Sum of noise octaves, normalized to zero mean and unit spread.
cv::Mat FractalNoise(cv::RNG& rng, int size, const std::vector<double>& scales_px, const std::vector<double>& weights) {
  cv::Mat sum = cv::Mat::zeros(size, size, CV_32F);
  for (size_t i = 0; i < scales_px.size(); ++i) {
    cv::Mat noise = NoiseOctave(rng, size, scales_px[i]);
    cv::Scalar mean, stddev;
    cv::meanStdDev(noise, mean, stddev);
    sum += (noise - mean[0]) * (weights[i] / std::max(stddev[0], 1e-9));
  }
  cv::Scalar mean, stddev;
  cv::meanStdDev(sum, mean, stddev);
  return (sum - mean[0]) / std::max(stddev[0], 1e-9);
}

// Colour image from a base colour (BGR) modulated by a noise field.
cv::Mat Tint(const cv::Mat& field, const cv::Vec3f& base_bgr, const cv::Vec3f& variation_bgr) {
  cv::Mat out(field.size(), CV_8UC3);
  for (int r = 0; r < field.rows; ++r) {
    for (int c = 0; c < field.cols; ++c) {
      const float f = field.at<float>(r, c);
      cv::Vec3b& px = out.at<cv::Vec3b>(r, c);
      for (int k = 0; k < 3; ++k) px[k] = cv::saturate_cast<uchar>(base_bgr[k] + f * variation_bgr[k]);
    }
  }
  return out;
}

// Draws with wrap-around so strokes crossing an edge continue on the other side.
template <typename DrawFn>
void DrawWrapped(cv::Mat& image, const cv::Point2f& p, DrawFn draw) {
  const float s = static_cast<float>(image.cols);
  for (int dx = -1; dx <= 1; ++dx) {
    for (int dy = -1; dy <= 1; ++dy) draw(cv::Point2f(p.x + dx * s, p.y + dy * s));
  }
}

cv::Mat Grass(cv::RNG& rng, int size) {
  cv::Mat field = FractalNoise(rng, size, {size / 8.0, size / 40.0, 6.0, 2.0}, {1.0, 0.7, 0.5, 0.4});
  cv::Mat image = Tint(field, {45, 120, 75}, {14, 30, 16});
  // Gaps where soil shows through and clumps of lighter, sunlit grass, a few cm across.
  const int patches = size * size / 900;
  for (int i = 0; i < patches; ++i) {
    const cv::Point2f p(rng.uniform(0.f, static_cast<float>(size)), rng.uniform(0.f, static_cast<float>(size)));
    const int radius = rng.uniform(2, 7);
    const bool gap = rng.uniform(0.0, 1.0) < 0.5;
    const cv::Scalar colour = gap ? cv::Scalar(25, 45, 50) : cv::Scalar(70, 170, 110);
    DrawWrapped(image, p, [&](cv::Point2f q) { cv::circle(image, q, radius, colour, -1, cv::LINE_AA); });
  }
  // Blades: short strokes, lighter and darker than the base, in random directions.
  const int blades = size * size / 25;
  for (int i = 0; i < blades; ++i) {
    const cv::Point2f p(rng.uniform(0.f, static_cast<float>(size)), rng.uniform(0.f, static_cast<float>(size)));
    const float angle = rng.uniform(0.f, static_cast<float>(CV_PI));
    const float length = rng.uniform(4.f, 14.f);
    const cv::Point2f d(std::cos(angle) * length, std::sin(angle) * length);
    const double shade = rng.uniform(-1.0, 1.0);
    const cv::Scalar colour(40 + 25 * shade, 115 + 70 * shade, 70 + 40 * shade);
    DrawWrapped(image, p, [&](cv::Point2f q) { cv::line(image, q, q + d, colour, 1, cv::LINE_AA); });
  }
  return image;
}

cv::Mat Gravel(cv::RNG& rng, int size) {
  cv::Mat field = FractalNoise(rng, size, {size / 10.0, 1.5}, {0.5, 1.0});
  cv::Mat image = Tint(field, {150, 160, 168}, {20, 20, 20});
  const int stones = size * size / 60;
  for (int i = 0; i < stones; ++i) {
    const cv::Point2f p(rng.uniform(0.f, static_cast<float>(size)), rng.uniform(0.f, static_cast<float>(size)));
    const cv::Size axes(rng.uniform(2, 7), rng.uniform(2, 6));
    const double g = rng.uniform(90.0, 220.0);
    const cv::Scalar colour(g * 0.95, g, g * 1.02);
    const double angle = rng.uniform(0.0, 180.0);
    DrawWrapped(image, p, [&](cv::Point2f q) { cv::ellipse(image, q, axes, angle, 0, 360, colour, -1, cv::LINE_AA); });
  }
  return image;
}

cv::Mat Pavement(cv::RNG& rng, int size) {
  // Concrete slabs of 50 cm (the tile covers 2 m): each slab its own tone, a granular speckle,
  // stains and lichen spots, dark joints.
  cv::Mat field = FractalNoise(rng, size, {size / 6.0, 10.0, 1.0}, {0.6, 0.6, 0.7});
  cv::Mat image = Tint(field, {150, 155, 160}, {16, 16, 16});
  const int slab = size / 4;
  for (int sx = 0; sx < 4; ++sx) {
    for (int sy = 0; sy < 4; ++sy) {
      const double tone = rng.uniform(-22.0, 22.0);
      cv::Mat part = image(cv::Rect(sx * slab, sy * slab, slab, slab));
      part += cv::Scalar(tone, tone, tone);
    }
  }
  const int speckles = size * size / 40;
  for (int i = 0; i < speckles; ++i) {
    const cv::Point p(rng.uniform(0, size), rng.uniform(0, size));
    const double g = rng.uniform(0.0, 1.0) < 0.5 ? rng.uniform(60.0, 110.0) : rng.uniform(190.0, 240.0);
    cv::circle(image, p, rng.uniform(1, 3), cv::Scalar(g, g, g * 1.02), -1, cv::LINE_AA);
  }
  const int stains = size * size / 6000;
  for (int i = 0; i < stains; ++i) {
    const cv::Point2f p(rng.uniform(0.f, static_cast<float>(size)), rng.uniform(0.f, static_cast<float>(size)));
    const bool lichen = rng.uniform(0.0, 1.0) < 0.5;
    const cv::Scalar colour = lichen ? cv::Scalar(120, 170, 175) : cv::Scalar(95, 100, 105);
    const cv::Size axes(rng.uniform(4, 16), rng.uniform(3, 12));
    const double angle = rng.uniform(0.0, 180.0);
    DrawWrapped(image, p, [&](cv::Point2f q) { cv::ellipse(image, q, axes, angle, 0, 360, colour, -1, cv::LINE_AA); });
  }
  for (int k = 0; k <= 4; ++k) {
    cv::line(image, {k * slab, 0}, {k * slab, size}, cv::Scalar(70, 75, 80), 4);
    cv::line(image, {0, k * slab}, {size, k * slab}, cv::Scalar(70, 75, 80), 4);
  }
  return image;
}

cv::Mat Soil(cv::RNG& rng, int size) {
  // Bark mulch: dark soil with scattered chips of lighter bark.
  cv::Mat field = FractalNoise(rng, size, {size / 12.0, 2.0}, {0.6, 0.8});
  cv::Mat image = Tint(field, {30, 45, 65}, {8, 12, 16});
  // Chips clearly lighter than the soil: on a dark ground a feature detector needs the contrast
  // (with dim chips the keypoint count swung 281-793 between seeds).
  const int chips = size * size / 40;
  for (int i = 0; i < chips; ++i) {
    const cv::Point2f p(rng.uniform(0.f, static_cast<float>(size)), rng.uniform(0.f, static_cast<float>(size)));
    const cv::Size axes(rng.uniform(3, 9), rng.uniform(1, 4));
    const double shade = rng.uniform(0.8, 1.6);
    const cv::Scalar colour(55 * shade, 90 * shade, 130 * shade);
    const double angle = rng.uniform(0.0, 180.0);
    DrawWrapped(image, p, [&](cv::Point2f q) { cv::ellipse(image, q, axes, angle, 0, 360, colour, -1, cv::LINE_AA); });
  }
  return image;
}

cv::Mat Leaves(cv::RNG& rng, int size, const cv::Vec3f& leaf_bgr, int leaf_px, int flowers) {
  cv::Mat field = FractalNoise(rng, size, {size / 16.0, 3.0}, {1.0, 0.5});
  cv::Mat image = Tint(field, {20, 45, 25}, {8, 14, 8});  // dark gaps between leaves
  const int leaves = size * size / (leaf_px * leaf_px / 3);
  for (int i = 0; i < leaves; ++i) {
    const cv::Point2f p(rng.uniform(0.f, static_cast<float>(size)), rng.uniform(0.f, static_cast<float>(size)));
    const cv::Size axes(rng.uniform(leaf_px / 2, leaf_px), rng.uniform(leaf_px / 4, leaf_px / 2 + 1));
    const double shade = rng.uniform(0.55, 1.25);
    const cv::Scalar colour(leaf_bgr[0] * shade, leaf_bgr[1] * shade, leaf_bgr[2] * shade);
    const double angle = rng.uniform(0.0, 180.0);
    DrawWrapped(image, p, [&](cv::Point2f q) { cv::ellipse(image, q, axes, angle, 0, 360, colour, -1, cv::LINE_AA); });
  }
  for (int i = 0; i < flowers; ++i) {
    const cv::Point2f p(rng.uniform(0.f, static_cast<float>(size)), rng.uniform(0.f, static_cast<float>(size)));
    const int radius = rng.uniform(leaf_px / 2, leaf_px + 2);
    const cv::Scalar colour(rng.uniform(40, 90), rng.uniform(30, 70), rng.uniform(170, 235));
    DrawWrapped(image, p, [&](cv::Point2f q) { cv::circle(image, q, radius, colour, -1, cv::LINE_AA); });
  }
  return image;
}

cv::Mat Bark(cv::RNG& rng, int size) {
  // Vertical furrows: noise stretched along the trunk.
  cv::Mat noise(size, size, CV_32F);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, 1.0);
  cv::Mat padded;
  cv::copyMakeBorder(noise, padded, 60, 60, 60, 60, cv::BORDER_WRAP);
  cv::GaussianBlur(padded, padded, cv::Size(0, 0), 1.5, 18.0);
  cv::Mat field = padded(cv::Rect(60, 60, size, size)).clone();
  cv::normalize(field, field, -2.0, 2.0, cv::NORM_MINMAX);
  field += FractalNoise(rng, size, {2.0}, {1.0}) * 0.3;
  return Tint(field, {45, 65, 85}, {14, 18, 22});
}

cv::Mat Wood(cv::RNG& rng, int size) {
  cv::Mat field = FractalNoise(rng, size, {1.0, 4.0}, {0.5, 0.5});
  // Boards 12.5 cm wide with grain along them.
  for (int r = 0; r < size; ++r) {
    for (int c = 0; c < size; ++c) {
      const int board = c / (size / 8);
      field.at<float>(r, c) += 0.8f * std::sin(0.05f * static_cast<float>(r) + 1.7f * static_cast<float>(board)) +
                               ((c % (size / 8)) < 3 ? -3.0f : 0.0f);
    }
  }
  return Tint(field, {70, 105, 135}, {12, 16, 20});
}

cv::Mat Stone(cv::RNG& rng, int size) {
  cv::Mat field = FractalNoise(rng, size, {size / 10.0, 8.0, 1.5}, {0.8, 0.6, 0.5});
  return Tint(field, {120, 125, 128}, {22, 22, 22});
}

}  // namespace

std::string ToString(Material m) {
  switch (m) {
    case Material::kGrass:
      return "grass";
    case Material::kGravel:
      return "gravel";
    case Material::kPavement:
      return "pavement";
    case Material::kSoil:
      return "soil";
    case Material::kFoliage:
      return "foliage";
    case Material::kRoseFoliage:
      return "rose_foliage";
    case Material::kTreeFoliage:
      return "tree_foliage";
    case Material::kBark:
      return "bark";
    case Material::kWood:
      return "wood";
    case Material::kStone:
      return "stone";
  }
  return "unknown";
}

Material GroundMaterial(Surface s) {
  switch (s) {
    case Surface::kGrass:
      return Material::kGrass;
    case Surface::kGravel:
      return Material::kGravel;
    case Surface::kPavement:
      return Material::kPavement;
    case Surface::kSoil:
      return Material::kSoil;
  }
  return Material::kGrass;
}

Material MaterialOf(ObjectClass c) {
  switch (c) {
    case ObjectClass::kTopiary:
    case ObjectClass::kHedge:
      return Material::kFoliage;
    case ObjectClass::kRose:
      return Material::kRoseFoliage;
    case ObjectClass::kTree:
      return Material::kTreeFoliage;
    case ObjectClass::kTrunk:
      return Material::kBark;
    case ObjectClass::kFence:
      return Material::kWood;
    default:
      return Material::kStone;
  }
}

double TileSize(Material m) {
  switch (m) {
    case Material::kGrass:
    case Material::kGravel:
    case Material::kSoil:
      return 4.0;
    case Material::kPavement:
      return 2.0;
    default:
      return 1.0;
  }
}

bool IsGround(Material m) {
  return m == Material::kGrass || m == Material::kGravel || m == Material::kSoil || m == Material::kPavement;
}

namespace {

cv::Mat Tile(Material material, cv::RNG& rng, int size_px) {
  switch (material) {
    case Material::kGrass:
      return Grass(rng, size_px);
    case Material::kGravel:
      return Gravel(rng, size_px);
    case Material::kPavement:
      return Pavement(rng, size_px);
    case Material::kSoil:
      return Soil(rng, size_px);
    case Material::kFoliage:
      return Leaves(rng, size_px, {30, 110, 45}, 14, 0);
    case Material::kRoseFoliage:
      return Leaves(rng, size_px, {35, 100, 55}, 18, size_px * size_px / 4000);
    case Material::kTreeFoliage:
      return Leaves(rng, size_px, {40, 140, 80}, 20, 0);
    case Material::kBark:
      return Bark(rng, size_px);
    case Material::kWood:
      return Wood(rng, size_px);
    case Material::kStone:
      return Stone(rng, size_px);
  }
  return {};
}

// 1 inside, 0 in a band along the border (8 % of the side), a smooth ramp over the next 8 %.
cv::Mat InteriorWeight(int size_px) {
  cv::Mat weight(size_px, size_px, CV_32F);
  const double band = 0.08 * size_px;
  for (int r = 0; r < size_px; ++r) {
    for (int c = 0; c < size_px; ++c) {
      const double d = std::min({r, c, size_px - 1 - r, size_px - 1 - c});
      const double t = std::clamp((d - band) / band, 0.0, 1.0);
      weight.at<float>(r, c) = static_cast<float>(t * t * (3.0 - 2.0 * t));
    }
  }
  return weight;
}

// The variant where `weight` is 1, the base where it is 0, contrast kept in between.
cv::Mat Crossfade(const cv::Mat& base, const cv::Mat& variant, const cv::Mat& weight, const cv::Scalar& mean) {
  const int size_px = base.rows;
  cv::Mat out(size_px, size_px, CV_8UC3);
  for (int r = 0; r < size_px; ++r) {
    for (int c = 0; c < size_px; ++c) {
      const float w = weight.at<float>(r, c);
      const float gain = 1.0f / std::sqrt((1.0f - w) * (1.0f - w) + w * w);
      const cv::Vec3f& b = base.at<cv::Vec3f>(r, c);
      const cv::Vec3f& v = variant.at<cv::Vec3f>(r, c);
      cv::Vec3b& o = out.at<cv::Vec3b>(r, c);
      for (int ch = 0; ch < 3; ++ch) {
        const auto m = static_cast<float>(mean[ch]);
        o[ch] = cv::saturate_cast<uchar>(m + gain * ((1.0f - w) * (b[ch] - m) + w * (v[ch] - m)));
      }
    }
  }
  return out;
}

}  // namespace

cv::Mat MakeTexture(Material material, std::uint64_t seed, int size_px) {
  cv::RNG rng(StreamSeed(seed, "texture/" + ToString(material)));
  return Tile(material, rng, size_px);
}

std::vector<cv::Mat> MakeGroundVariants(Material material, std::uint64_t seed, int size_px) {
  if (!IsGround(material))
    throw std::invalid_argument("MakeGroundVariants: " + ToString(material) + " is not a ground");
  // Each a tile of the variant's own seed inside, crossfaded to the base tile at the border. The
  // blend of two independent textures would lose contrast in the ramp (by up to 1/sqrt(2)): the
  // deviation from the mean is scaled back by 1 / sqrt((1 - w)^2 + w^2), so features are as strong there.
  cv::Mat base;
  MakeTexture(material, seed, size_px).convertTo(base, CV_32FC3);
  const cv::Mat weight = InteriorWeight(size_px);
  const cv::Scalar mean = cv::mean(base);
  std::vector<cv::Mat> variants;
  for (int k = 0; k < kGroundVariants; ++k) {
    cv::Mat variant;
    cv::RNG rng(StreamSeed(seed, "texture/" + ToString(material) + "/variant" + std::to_string(k)));
    Tile(material, rng, size_px).convertTo(variant, CV_32FC3);
    variants.push_back(Crossfade(base, variant, weight, mean));
  }
  return variants;
}

}  // namespace trimbot::garden
