#include "exitance/runtime/view/view_camera.h"

#include <cmath>
#include <numbers>

#include "exitance/runtime/matrix4d.h"
#include "exitance/runtime/view/view_input_error.h"

namespace exitance::view {
namespace {

bool finite(Vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// The node's world matrix: its ancestors' local transforms composed root first, as the importer does.
Matrix4d node_world(const formats::SceneFile& scene, int32_t node) {
  Matrix4d world = kIdentityMatrix4d;
  // scene.bin's reader refused cycles and hierarchies deeper than 257 levels.
  for (int32_t at = node; at >= 0; at = scene.nodes[size_t(at)].parent) {
    const formats::NodeRecord& n = scene.nodes[size_t(at)];
    world = multiply(n.has_matrix ? n.matrix : trs_matrix(n.translation, n.rotation, n.scale), world);
  }
  return world;
}

Vec3 transform_direction(const Matrix4d& m, Vec3 d) {
  return {float(m[0] * d.x + m[4] * d.y + m[8] * d.z), float(m[1] * d.x + m[5] * d.y + m[9] * d.z),
          float(m[2] * d.x + m[6] * d.y + m[10] * d.z)};
}

}  // namespace

PinholeCamera look_at_camera(Vec3 look_from, Vec3 look_at, Vec3 up, double yfov) {
  if (!(yfov > 0 && yfov < std::numbers::pi))
    throw ViewInputError("--yfov: " + std::to_string(yfov) + " radians is not within (0, pi)");
  if (!finite(look_from)) throw ViewInputError("--look-from: is not finite");
  if (!finite(look_at)) throw ViewInputError("--look-at: is not finite");
  if (!finite(up)) throw ViewInputError("--up: is not finite");
  const Vec3 view = look_at - look_from;
  if (!(length(view) > 0)) throw ViewInputError("--look-at: equals --look-from (no view direction)");
  if (!(length(up) > 0)) throw ViewInputError("--up: is the zero vector");
  const Vec3 forward = normalize(view);
  const Vec3 side = cross(forward, normalize(up));
  // sin of the angle between up and the view direction; below 1e-6 the image's roll is undefined.
  if (!(length(side) > 1e-6f)) throw ViewInputError("--up: is parallel to the view direction");
  PinholeCamera camera;
  camera.eye = look_from;
  camera.forward = forward;
  camera.right = normalize(side);
  camera.up = cross(camera.right, forward);
  camera.tan_half_yfov = std::tan(yfov / 2);
  return camera;
}

GltfCameraView gltf_camera(const formats::SceneFile& scene, const std::string& name) {
  const formats::CameraRecord* found = nullptr;
  for (const auto& c : scene.cameras)
    if (c.name == name) found = found ? found : &c;
  if (!found)
    for (const auto& c : scene.cameras)
      if (c.node >= 0 && scene.nodes[size_t(c.node)].name == name) found = found ? found : &c;
  if (!found) {
    std::string names;
    for (const auto& c : scene.cameras) {
      const std::string node_name = c.node >= 0 ? scene.nodes[size_t(c.node)].name : "";
      names += (names.empty() ? "" : ", ") + ("\"" + c.name + "\"") +
               (node_name.empty() || node_name == c.name ? "" : " (node \"" + node_name + "\")");
    }
    throw ViewInputError("--camera: no camera named \"" + name + "\" in scene.bin (cameras: " +
                         (names.empty() ? "none" : names) + ")");
  }
  if (found->node < 0 || !scene.nodes[size_t(found->node)].in_scene)
    throw ViewInputError("--camera: \"" + name + "\" is not placed by a node of the default scene");
  const Matrix4d world = node_world(scene, found->node);
  const Vec3 eye{float(world[12]), float(world[13]), float(world[14])};
  const Vec3 forward = transform_direction(world, {0, 0, -1}), up = transform_direction(world, {0, 1, 0});
  const bool orthographic = found->type == formats::CameraType::Orthographic;
  if (orthographic && !(found->xmag > 0 && found->ymag > 0 && std::isfinite(found->xmag) && std::isfinite(found->ymag)))
    throw ViewInputError("--camera: \"" + name + "\" is orthographic with xmag " + std::to_string(found->xmag) +
                         ", ymag " + std::to_string(found->ymag) + ": both must be positive");
  try {
    // An orthographic camera's yfov is unused: any valid angle lets look_at_camera build the frame.
    GltfCameraView view{look_at_camera(eye, eye + forward, up, orthographic ? 1.0 : found->yfov),
                        orthographic ? found->xmag / found->ymag : found->aspect_ratio};
    view.camera.orthographic = orthographic;
    view.camera.ortho_half_height = orthographic ? found->ymag : 1.0;
    return view;
  } catch (const ViewInputError& e) {
    throw ViewInputError("--camera: \"" + name + "\": its node's transform gives no view (" + e.what() + ")");
  }
}

Vec3 primary_ray_direction(const PinholeCamera& camera, double x, double y, int width, int height) {
  const double aspect = double(width) / double(height);
  const double sx = (2 * x / width - 1) * camera.tan_half_yfov * aspect;
  const double sy = (1 - 2 * y / height) * camera.tan_half_yfov;
  return normalize(camera.forward + camera.right * float(sx) + camera.up * float(sy));
}

PrimaryRay primary_ray(const PinholeCamera& camera, double x, double y, int width, int height) {
  if (!camera.orthographic) return {camera.eye, primary_ray_direction(camera, x, y, width, height)};
  const double aspect = double(width) / double(height);
  const double sx = (2 * x / width - 1) * camera.ortho_half_height * aspect;
  const double sy = (1 - 2 * y / height) * camera.ortho_half_height;
  return {camera.eye + camera.right * float(sx) + camera.up * float(sy), camera.forward};
}

}  // namespace exitance::view
