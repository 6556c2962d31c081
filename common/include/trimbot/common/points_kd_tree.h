#pragma once
// A nanoflann k-d tree over a vector of 3-D points (the vector must outlive the tree): the one
// adaptor registration and the map evaluation share.
#include <Eigen/Core>
#include <nanoflann.hpp>

#include <cstdint>
#include <vector>

namespace trimbot {

struct PointsAdaptor {
  const std::vector<Eigen::Vector3d>& points;
  std::size_t kdtree_get_point_count() const { return points.size(); }
  double kdtree_get_pt(std::size_t i, std::size_t dim) const { return points[i][static_cast<int>(dim)]; }
  template <class BBox>
  bool kdtree_get_bbox(BBox&) const {
    return false;
  }
};
using PointsKdTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, PointsAdaptor>,
                                                         PointsAdaptor, 3, std::uint32_t>;

}  // namespace trimbot
