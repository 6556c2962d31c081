#include "trimbot/robot/collision_model.h"

#include <fcl/fcl.h>
#include <octomap/octomap.h>

#include <algorithm>
#include <limits>
#include <map>
#include <numeric>
#include <stdexcept>

#include "trimbot/common/input_error.h"

namespace trimbot::robot {
namespace {

using Geometry = std::shared_ptr<fcl::CollisionGeometryd>;

// The URDF's collision geometry grown by `padding` on every side.
Geometry UrdfGeometry(const urdf::Geometry& g, const std::string& urdf_path, const std::string& link,
                      double padding = 0.0) {
  switch (g.type) {
    case urdf::Geometry::BOX: {
      const auto& box = static_cast<const urdf::Box&>(g);
      return std::make_shared<fcl::Boxd>(box.dim.x + 2.0 * padding, box.dim.y + 2.0 * padding,
                                         box.dim.z + 2.0 * padding);
    }
    case urdf::Geometry::CYLINDER: {
      const auto& cylinder = static_cast<const urdf::Cylinder&>(g);
      return std::make_shared<fcl::Cylinderd>(cylinder.radius + padding, cylinder.length + 2.0 * padding);
    }
    case urdf::Geometry::SPHERE:
      return std::make_shared<fcl::Sphered>(static_cast<const urdf::Sphere&>(g).radius + padding);
    default:
      throw InputError(urdf_path, "link '" + link + "': only box, cylinder and sphere collision geometry is supported");
  }
}

// Disjoint sets of links joined by fixed joints: each set moves as one rigid body.
int Find(std::vector<int>& parent, int i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

}  // namespace

// ---------------------------------------------------------------- environment

struct CollisionEnvironment::Objects {
  std::vector<std::string> names;
  std::vector<std::unique_ptr<fcl::CollisionObjectd>> objects;
  void Add(const std::string& name, Geometry geometry, const Eigen::Isometry3d& pose) {
    auto object = std::make_unique<fcl::CollisionObjectd>(std::move(geometry), pose.rotation(), pose.translation());
    object->computeAABB();
    names.push_back(name);
    objects.push_back(std::move(object));
  }
};

CollisionEnvironment::CollisionEnvironment() : objects_(std::make_unique<Objects>()) {}
CollisionEnvironment::~CollisionEnvironment() = default;
CollisionEnvironment::CollisionEnvironment(CollisionEnvironment&&) noexcept = default;
CollisionEnvironment& CollisionEnvironment::operator=(CollisionEnvironment&&) noexcept = default;

void CollisionEnvironment::Clear() { *objects_ = Objects(); }
int CollisionEnvironment::size() const { return static_cast<int>(objects_->objects.size()); }
const std::string& CollisionEnvironment::name(int index) const { return objects_->names.at(index); }

void CollisionEnvironment::AddBox(const std::string& name, const Eigen::Vector3d& size, const Eigen::Isometry3d& pose) {
  objects_->Add(name, std::make_shared<fcl::Boxd>(size), pose);
}

void CollisionEnvironment::AddCylinder(const std::string& name, double radius, double length,
                                       const Eigen::Isometry3d& pose) {
  objects_->Add(name, std::make_shared<fcl::Cylinderd>(radius, length), pose);
}

void CollisionEnvironment::AddEllipsoid(const std::string& name, const Eigen::Vector3d& radii,
                                        const Eigen::Isometry3d& pose) {
  objects_->Add(name, std::make_shared<fcl::Ellipsoidd>(radii), pose);
}

void CollisionEnvironment::AddSphere(const std::string& name, double radius, const Eigen::Vector3d& centre) {
  objects_->Add(name, std::make_shared<fcl::Sphered>(radius), Eigen::Isometry3d(Eigen::Translation3d(centre)));
}

void CollisionEnvironment::AddMesh(const std::string& name, const std::vector<Eigen::Vector3d>& vertices,
                                   const std::vector<std::array<int, 3>>& triangles, const Eigen::Isometry3d& pose) {
  auto model = std::make_shared<fcl::BVHModel<fcl::OBBRSSd>>();
  std::vector<fcl::Triangle> faces;
  faces.reserve(triangles.size());
  for (const auto& t : triangles) faces.emplace_back(t[0], t[1], t[2]);
  model->beginModel();
  model->addSubModel(vertices, faces);
  model->endModel();
  objects_->Add(name, model, pose);
}

void CollisionEnvironment::AddConvex(const std::string& name, const std::vector<Eigen::Vector3d>& vertices,
                                     const std::vector<std::array<int, 3>>& triangles) {
  auto points = std::make_shared<std::vector<fcl::Vector3d>>(vertices.begin(), vertices.end());
  auto faces = std::make_shared<std::vector<int>>();
  for (const auto& t : triangles) faces->insert(faces->end(), {3, t[0], t[1], t[2]});
  objects_->Add(name, std::make_shared<fcl::Convexd>(points, static_cast<int>(triangles.size()), faces),
                Eigen::Isometry3d::Identity());
}

double CollisionEnvironment::DistanceTo(int index, const Eigen::Vector3d& point) const {
  const fcl::CollisionObjectd probe(std::make_shared<fcl::Sphered>(1e-9), Eigen::Matrix3d::Identity(), point);
  fcl::DistanceRequestd request;
  request.gjk_solver_type = fcl::GST_INDEP;
  fcl::DistanceResultd result;
  const double d = fcl::distance(objects_->objects.at(static_cast<size_t>(index)).get(), &probe, request, result);
  return std::max(0.0, d);
}

void CollisionEnvironment::AddGround(const std::string& name, double height) {
  // A thick slab rather than an FCL half-space: every shape pair has a distance query with a box.
  constexpr double kExtent = 200.0, kDepth = 1.0;
  objects_->Add(name, std::make_shared<fcl::Boxd>(kExtent, kExtent, kDepth),
                Eigen::Isometry3d(Eigen::Translation3d(0.0, 0.0, height - 0.5 * kDepth)));
}

void CollisionEnvironment::AddOccupiedPoints(const std::string& name, const std::vector<Eigen::Vector3d>& points,
                                             double resolution) {
  if (points.empty()) return;
  auto tree = std::make_shared<octomap::OcTree>(resolution);
  for (const auto& p : points) tree->updateNode(octomap::point3d(p.x(), p.y(), p.z()), true);
  tree->updateInnerOccupancy();
  objects_->Add(name, std::make_shared<fcl::OcTreed>(std::shared_ptr<const octomap::OcTree>(tree)),
                Eigen::Isometry3d::Identity());
}

// ---------------------------------------------------------------- robot

struct CollisionModel::Robot {
  struct Link {
    std::string name;
    int parent = -1;                     // index, -1 for the root
    const urdf::Joint* joint = nullptr;  // from the parent
    int varied = -1;                     // index into q, or -1 (joint held at zero)
    bool moving = false;                 // a varied joint lies between it and the root
  };
  struct Shape {
    int link = 0;
    std::string label;
    Eigen::Isometry3d origin;  // in the link
    std::unique_ptr<fcl::CollisionObjectd> object;
    // A link of the robot's body (not moved by the varied joints): grown by the body clearance, as
    // the moving links see it.
    std::unique_ptr<fcl::CollisionObjectd> padded;
  };
  std::vector<Link> links;  // parents before children
  std::vector<Shape> shapes;
  std::vector<std::pair<int, int>> self_pairs;  // shape indices
  std::vector<int> moving_shapes, static_shapes;

  // The URDF's links in breadth-first order from the root, with the joints in `varied_joints` free.
  void AddLinkTree(const urdf::ModelInterface& urdf, const std::vector<std::string>& varied_joints) {
    std::map<std::string, int> index;
    std::vector<urdf::LinkConstSharedPtr> queue{urdf.getRoot()};
    for (size_t k = 0; k < queue.size(); ++k) {
      const auto& link = queue[k];
      Link node;
      node.name = link->name;
      if (link->parent_joint) {
        node.parent = index.at(link->parent_joint->parent_link_name);
        node.joint = link->parent_joint.get();
        const auto varied = std::find(varied_joints.begin(), varied_joints.end(), node.joint->name);
        if (varied != varied_joints.end()) node.varied = static_cast<int>(varied - varied_joints.begin());
        node.moving = node.varied >= 0 || links[node.parent].moving;
      }
      index[node.name] = static_cast<int>(links.size());
      links.push_back(node);
      for (const auto& child : link->child_links) queue.push_back(child);
    }
  }

  std::vector<Eigen::Isometry3d> LinkPoses(const Eigen::VectorXd& q, const Eigen::Isometry3d& root) const {
    std::vector<Eigen::Isometry3d> poses(links.size());
    for (size_t i = 0; i < links.size(); ++i) {
      const Link& link = links[i];
      if (link.parent < 0) {
        poses[i] = root;
        continue;
      }
      poses[i] =
          poses[link.parent] * RobotDescription::JointTransform(*link.joint, link.varied >= 0 ? q[link.varied] : 0.0);
    }
    return poses;
  }
};

CollisionModel::CollisionModel(const RobotDescription& description, const std::vector<std::string>& varied_joints,
                               double body_clearance)
    : robot_(std::make_unique<Robot>()) {
  if (!(body_clearance >= 0.0)) throw std::invalid_argument("CollisionModel: the body clearance is negative");
  const urdf::ModelInterface& urdf = description.urdf();
  robot_->AddLinkTree(urdf, varied_joints);
  for (const auto& name : varied_joints) {
    if (!urdf.getJoint(name)) throw InputError(description.path(), "no joint named '" + name + "'");
  }

  // Rigid bodies (fixed joints) and the bodies one moving joint apart.
  const int n = static_cast<int>(robot_->links.size());
  std::vector<int> body(n);
  std::iota(body.begin(), body.end(), 0);
  for (int i = 0; i < n; ++i) {
    const auto& link = robot_->links[i];
    if (link.joint && link.joint->type == urdf::Joint::FIXED) body[Find(body, i)] = Find(body, link.parent);
  }
  auto adjacent = [&](int a, int b) {
    const int ba = Find(body, a), bb = Find(body, b);
    if (ba == bb) return true;
    for (int i = 0; i < n; ++i) {  // a moving joint whose parent is in one body and child in the other
      const auto& link = robot_->links[i];
      if (!link.joint || link.joint->type == urdf::Joint::FIXED) continue;
      const int child = Find(body, i), parent = Find(body, link.parent);
      if ((child == ba && parent == bb) || (child == bb && parent == ba)) return true;
    }
    return false;
  };

  for (int i = 0; i < n; ++i) {
    const auto link = urdf.getLink(robot_->links[i].name);
    int k = 0;
    for (const auto& collision : link->collision_array) {
      if (!collision || !collision->geometry) continue;
      Robot::Shape shape;
      shape.link = i;
      shape.label = link->name + (link->collision_array.size() > 1 ? "/" + std::to_string(k) : "");
      shape.origin = ToIsometry(collision->origin);
      shape.object =
          std::make_unique<fcl::CollisionObjectd>(UrdfGeometry(*collision->geometry, description.path(), link->name));
      if (!robot_->links[i].moving) {
        shape.padded = std::make_unique<fcl::CollisionObjectd>(
            UrdfGeometry(*collision->geometry, description.path(), link->name, body_clearance));
      }
      (robot_->links[i].moving ? robot_->moving_shapes : robot_->static_shapes)
          .push_back(static_cast<int>(robot_->shapes.size()));
      robot_->shapes.push_back(std::move(shape));
      ++k;
    }
  }
  for (int s : robot_->moving_shapes) {
    const std::string& name = robot_->links[robot_->shapes[s].link].name;
    if (std::find(moving_link_names_.begin(), moving_link_names_.end(), name) == moving_link_names_.end()) {
      moving_link_names_.push_back(name);
    }
  }
  for (size_t a = 0; a < robot_->shapes.size(); ++a) {
    for (size_t b = a + 1; b < robot_->shapes.size(); ++b) {
      const auto& sa = robot_->shapes[a];
      const auto& sb = robot_->shapes[b];
      if (!robot_->links[sa.link].moving && !robot_->links[sb.link].moving) continue;  // never changes
      if (adjacent(sa.link, sb.link)) {
        allowed_pair_names_.emplace_back(sa.label, sb.label);
      } else {
        robot_->self_pairs.emplace_back(static_cast<int>(a), static_cast<int>(b));
        checked_pair_names_.emplace_back(sa.label, sb.label);
      }
    }
  }
}

CollisionModel::~CollisionModel() = default;
CollisionModel::CollisionModel(CollisionModel&&) noexcept = default;
CollisionModel& CollisionModel::operator=(CollisionModel&&) noexcept = default;

CollisionReport CollisionModel::Check(const Eigen::VectorXd& q, const CollisionCheckOptions& options,
                                      const Eigen::Isometry3d& T_frame_base) const {
  Robot& robot = *robot_;
  const std::vector<Eigen::Isometry3d> poses = robot.LinkPoses(q, T_frame_base);
  for (auto& shape : robot.shapes) {
    const Eigen::Isometry3d pose = poses[shape.link] * shape.origin;
    shape.object->setTransform(pose.rotation(), pose.translation());
    shape.object->computeAABB();
    if (shape.padded) {
      shape.padded->setTransform(pose.rotation(), pose.translation());
      shape.padded->computeAABB();
    }
  }

  CollisionReport report;
  report.clearance = std::numeric_limits<double>::infinity();
  fcl::CollisionRequestd collision_request;
  fcl::DistanceRequestd distance_request;
  distance_request.gjk_solver_type = fcl::GST_INDEP;  // libccd's GJK stops ~0.3 mm short on the ground slab
  // Returns true to stop: a contact when no clearance is wanted.
  auto test = [&](const fcl::CollisionObjectd& a, const fcl::CollisionObjectd& b, const std::string& name_a,
                  const std::string& name_b) {
    if (!options.distance && !a.getAABB().overlap(b.getAABB())) return false;
    fcl::CollisionResultd result;
    if (fcl::collide(&a, &b, collision_request, result) > 0) {
      if (!report.collision) report.pair = {name_a, name_b};
      report.collision = true;
      report.clearance = 0.0;
      report.closest = report.pair;
      return true;
    }
    if (options.distance) {
      fcl::DistanceResultd distance;
      const double d = fcl::distance(&a, &b, distance_request, distance);
      if (d < report.clearance) {
        report.clearance = d;
        report.closest = {name_a, name_b};
      }
    }
    return false;
  };

  if (options.self) {
    for (const auto& [a, b] : robot.self_pairs) {
      const Robot::Shape &sa = robot.shapes[a], &sb = robot.shapes[b];
      // A moving link against the body keeps the body clearance (one of the two does not move).
      const fcl::CollisionObjectd& oa = sa.padded ? *sa.padded : *sa.object;
      const fcl::CollisionObjectd& ob = sb.padded ? *sb.padded : *sb.object;
      if (test(oa, ob, sa.label, sb.label)) return report;
    }
  }
  if (options.environment) {
    const auto& environment = *environment_.objects_;
    auto against_environment = [&](const std::vector<int>& shapes) {
      for (int s : shapes) {
        for (size_t e = 0; e < environment.objects.size(); ++e) {
          if (test(*robot.shapes[s].object, *environment.objects[e], robot.shapes[s].label, environment.names[e])) {
            return true;
          }
        }
      }
      return false;
    };
    if (against_environment(robot.moving_shapes)) return report;
    if (options.static_links_against_environment && against_environment(robot.static_shapes)) return report;
  }
  if (!options.distance) report.clearance = 0.0;
  return report;
}

}  // namespace trimbot::robot
