#include "trimbot/garden/object_mesh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "trimbot/common/random.h"
#include "trimbot/garden/conditions.h"
#include "trimbot/garden/foliage.h"
#include "trimbot/garden/textures.h"

namespace trimbot::garden {
namespace {

double Smooth(double t) { return t * t * (3.0 - 2.0 * t); }

double LatticeValue(std::uint64_t seed, long x, long y, long z) {
  std::uint64_t h = SplitMix64(seed ^ SplitMix64(static_cast<std::uint64_t>(x) * 0x9E3779B1ULL));
  h = SplitMix64(h ^ static_cast<std::uint64_t>(y) * 0x85EBCA77ULL);
  h = SplitMix64(h ^ static_cast<std::uint64_t>(z) * 0xC2B2AE3DULL);
  return static_cast<double>(h >> 11) / static_cast<double>(1ULL << 53) * 2.0 - 1.0;
}

// Adds a quad (a, b, c, d counter-clockwise from outside) to a mesh.
void Quad(Mesh& mesh, int a, int b, int c, int d) {
  mesh.faces.push_back({a, b, c});
  mesh.faces.push_back({a, c, d});
}

Mesh CylinderMesh(const Eigen::Vector3d& size, double tile) {
  Mesh mesh;
  constexpr int kSegments = 24;
  const double rx = size.x() / 2, ry = size.y() / 2, h = size.z();
  // Side: a column of vertices per segment, the seam duplicated for the texture.
  for (int i = 0; i <= kSegments; ++i) {
    const double a = 2.0 * M_PI * i / kSegments;
    const double u = a * 0.5 * (rx + ry) / tile;
    mesh.vertices.push_back({rx * std::cos(a), ry * std::sin(a), 0.0});
    mesh.texcoords.push_back({u, 0.0});
    mesh.vertices.push_back({rx * std::cos(a), ry * std::sin(a), h});
    mesh.texcoords.push_back({u, h / tile});
  }
  for (int i = 0; i < kSegments; ++i) Quad(mesh, 2 * i, 2 * i + 2, 2 * i + 3, 2 * i + 1);
  // Caps: fans around a centre vertex.
  for (const double z : {0.0, h}) {
    const int centre = static_cast<int>(mesh.vertices.size());
    mesh.vertices.push_back({0.0, 0.0, z});
    mesh.texcoords.push_back({0.0, 0.0});
    for (int i = 0; i < kSegments; ++i) {
      const double a = 2.0 * M_PI * i / kSegments;
      mesh.vertices.push_back({rx * std::cos(a), ry * std::sin(a), z});
      mesh.texcoords.push_back({rx * std::cos(a) / tile, ry * std::sin(a) / tile});
    }
    for (int i = 0; i < kSegments; ++i) {
      const int a = centre + 1 + i, b = centre + 1 + (i + 1) % kSegments;
      if (z == 0.0) {
        mesh.faces.push_back({centre, b, a});
      } else {
        mesh.faces.push_back({centre, a, b});
      }
    }
  }
  return mesh;
}

// A superellipsoid of the object's shape (exponent 2 = round, larger = flatter sides), its surface
// where FoliageGrowth puts the leaves (the target pushed out by leaf clumps and growth).
Mesh SuperellipsoidMesh(const GardenObject& object, std::uint64_t seed, double growth) {
  const FoliageGrowth foliage(object, seed, growth);
  const Eigen::Vector3d half = foliage.target().half;
  const double tile = TileSize(MaterialOf(object.object_class));

  Mesh mesh;
  constexpr int kRings = 24, kSegments = 48;
  for (int r = 0; r <= kRings; ++r) {
    const double polar = M_PI * r / kRings;
    for (int s = 0; s <= kSegments; ++s) {
      const double azimuth = 2.0 * M_PI * s / kSegments;
      const Eigen::Vector3d d(std::sin(polar) * std::cos(azimuth), std::sin(polar) * std::sin(azimuth),
                              std::cos(polar));
      // Never below the bottom (it sits on the ground or its stem).
      Eigen::Vector3d p = foliage.SurfacePoint(d);
      p.z() = std::max(p.z(), -half.z());
      mesh.vertices.push_back(p + Eigen::Vector3d(0, 0, half.z()));
      const double circumference = M_PI * (half.x() + half.y());
      mesh.texcoords.push_back({azimuth / (2.0 * M_PI) * circumference / tile, polar / M_PI * 2.0 * half.z() / tile});
    }
  }
  const int row = kSegments + 1;
  for (int r = 0; r < kRings; ++r) {
    for (int s = 0; s < kSegments; ++s) {
      const int a = r * row + s, b = a + 1, c = a + row + 1, d = a + row;
      // Rows at the poles collapse to a point: one triangle each there.
      // (a, d, c, b) runs counter-clockwise seen from outside (polar x azimuth = outward).
      if (r == 0) {
        mesh.faces.push_back({a, d, c});
      } else if (r == kRings - 1) {
        mesh.faces.push_back({a, d, b});
      } else {
        Quad(mesh, a, d, c, b);
      }
    }
  }
  return mesh;
}

}  // namespace

double ValueNoise(std::uint64_t seed, const Eigen::Vector3d& p) {
  const Eigen::Vector3d f = p.array().floor();
  const long x = static_cast<long>(f.x()), y = static_cast<long>(f.y()), z = static_cast<long>(f.z());
  const double tx = Smooth(p.x() - f.x()), ty = Smooth(p.y() - f.y()), tz = Smooth(p.z() - f.z());
  double value = 0.0;
  for (int dx = 0; dx <= 1; ++dx) {
    for (int dy = 0; dy <= 1; ++dy) {
      for (int dz = 0; dz <= 1; ++dz) {
        const double w = (dx ? tx : 1 - tx) * (dy ? ty : 1 - ty) * (dz ? tz : 1 - tz);
        value += w * LatticeValue(seed, x + dx, y + dy, z + dz);
      }
    }
  }
  return value;
}

double Mesh::Area() const {
  double area = 0.0;
  for (const auto& f : faces) {
    area += 0.5 * (vertices[f[1]] - vertices[f[0]]).cross(vertices[f[2]] - vertices[f[0]]).norm();
  }
  return area;
}

Mesh BoxMesh(const Eigen::Vector3d& size, double tile) {
  Mesh mesh;
  const Eigen::Vector3d h = size / 2.0;
  // Each face: an outward axis, and two in-face axes (u, v) forming a right-handed frame.
  const std::array<std::array<Eigen::Vector3d, 3>, 6> faces = {{
      {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ()},
      {-Eigen::Vector3d::UnitX(), -Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ()},
      {Eigen::Vector3d::UnitY(), -Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitZ()},
      {-Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitZ()},
      {Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY()},
      {-Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitX()},
  }};
  for (const auto& [normal, u, v] : faces) {
    const int first = static_cast<int>(mesh.vertices.size());
    for (const auto& [su, sv] : std::array<std::pair<double, double>, 4>{{{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}}) {
      const Eigen::Vector3d p = normal.cwiseProduct(h) + su * u.cwiseProduct(h).cwiseAbs().norm() * u +
                                sv * v.cwiseProduct(h).cwiseAbs().norm() * v;
      mesh.vertices.push_back(p + Eigen::Vector3d(0, 0, h.z()));
      mesh.texcoords.push_back({p.dot(u) / tile, p.dot(v) / tile});
    }
    Quad(mesh, first, first + 1, first + 2, first + 3);
  }
  return mesh;
}

std::vector<Mesh> LawnMeshes(const Eigen::Vector2d& min, const Eigen::Vector2d& max, double tile, std::uint64_t seed) {
  const int columns = std::max(1, static_cast<int>(std::ceil((max.x() - min.x()) / tile - 1e-9)));
  const int rows = std::max(1, static_cast<int>(std::ceil((max.y() - min.y()) / tile - 1e-9)));
  const auto pick = [&](const char* what, long i, long j) {
    return SplitMix64(StreamSeed(seed, what) ^
                      SplitMix64(static_cast<std::uint64_t>(i) * 0x9E3779B1ULL + static_cast<std::uint64_t>(j)));
  };
  std::vector<Mesh> meshes(kGroundVariants);
  for (int j = 0; j < rows; ++j) {
    const bool mirror_v = (pick("lawn/row", j, 0) & 1U) != 0;
    for (int i = 0; i < columns; ++i) {
      const bool mirror_u = (pick("lawn/column", i, 0) & 1U) != 0;
      Mesh& mesh = meshes[pick("lawn/variant", i, j) % kGroundVariants];
      const double x0 = min.x() + i * tile, y0 = min.y() + j * tile, x1 = x0 + tile, y1 = y0 + tile,
                   z = -kGroundSlabDepth;
      // Top: the whole variant, mirrored as drawn; sides and bottom close the slab (MuJoCo wants
      // meshes with a volume) and are never seen.
      const double u0 = mirror_u ? 1.0 : 0.0, v0 = mirror_v ? 1.0 : 0.0;
      const std::array<std::array<Eigen::Vector3d, 4>, 6> quads = {{
          {{{x0, y0, 0}, {x1, y0, 0}, {x1, y1, 0}, {x0, y1, 0}}},  // top, seen from above
          {{{x0, y0, z}, {x0, y1, z}, {x1, y1, z}, {x1, y0, z}}},  // bottom, seen from below
          {{{x0, y0, z}, {x1, y0, z}, {x1, y0, 0}, {x0, y0, 0}}},  // -y side
          {{{x1, y1, z}, {x0, y1, z}, {x0, y1, 0}, {x1, y1, 0}}},  // +y side
          {{{x0, y1, z}, {x0, y0, z}, {x0, y0, 0}, {x0, y1, 0}}},  // -x side
          {{{x1, y0, z}, {x1, y1, z}, {x1, y1, 0}, {x1, y0, 0}}},  // +x side
      }};
      for (std::size_t q = 0; q < quads.size(); ++q) {
        const int corner = static_cast<int>(mesh.vertices.size());
        for (const auto& p : quads[q]) {
          mesh.vertices.push_back(p);
          mesh.texcoords.emplace_back(
              q == 0 ? Eigen::Vector2d(std::abs(u0 - (p.x() - x0) / tile), std::abs(v0 - (p.y() - y0) / tile))
                     : Eigen::Vector2d(0.0, 0.0));
        }
        Quad(mesh, corner, corner + 1, corner + 2, corner + 3);
      }
    }
  }
  return meshes;
}

Mesh ObjectMesh(const GardenObject& object, std::uint64_t seed, double growth) {
  if (IsFoliage(object.object_class)) {
    return SuperellipsoidMesh(object, seed, growth);
  }
  const double tile = TileSize(MaterialOf(object.object_class));
  switch (object.shape) {
    case Shape::kEllipsoid:
      return SuperellipsoidMesh(object, seed, 0.0);
    case Shape::kCylinder:
      return CylinderMesh(object.size, tile);
    case Shape::kBox:
      return object.object_class == ObjectClass::kTrunk ? CylinderMesh(object.size, tile) : BoxMesh(object.size, tile);
  }
  return {};
}

Eigen::Matrix4d ObjectPose(const GardenObject& object) {
  Eigen::Matrix4d pose = Eigen::Matrix4d::Identity();
  pose(0, 0) = std::cos(object.yaw);
  pose(0, 1) = -std::sin(object.yaw);
  pose(1, 0) = std::sin(object.yaw);
  pose(1, 1) = std::cos(object.yaw);
  pose(0, 3) = object.position.x();
  pose(1, 3) = object.position.y();
  pose(2, 3) = object.base_height;
  return pose;
}

}  // namespace trimbot::garden
