// The camera of exitance-view: from --look-from/--look-at/--up/--yfov, or from a glTF camera node
// recorded in scene.bin (a camera looks down its node's -Z with +Y up; perspective or orthographic).
#pragma once
#include <optional>
#include <string>

#include "exitance/formats/scene_file.h"
#include "exitance/runtime/vec_math.h"

namespace exitance::view {

struct PinholeCamera {
  Vec3 eye;
  Vec3 forward, right, up;  // orthonormal, right-handed: right = forward x up
  double tan_half_yfov = 1;
  // glTF orthographic: parallel rays along `forward` from the plane through `eye`, the image
  // spanning ortho_half_height above and below the centre (glTF ymag) and that times the image's
  // aspect ratio to either side.
  bool orthographic = false;
  double ortho_half_height = 1;
};

// Throws ViewInputError naming the option: yfov not in (0, pi), look-from == look-at, a zero up or
// an up parallel to the view direction, non-finite values.
PinholeCamera look_at_camera(Vec3 look_from, Vec3 look_at, Vec3 up, double yfov);

struct GltfCameraView {
  PinholeCamera camera;
  float aspect_ratio = 0;  // width / height as the glTF gives it; 0 when not given
};

// The camera named `name` (a glTF camera's name, or else the name of the node that places it);
// for an orthographic camera aspect_ratio is xmag / ymag. Throws ViewInputError listing the
// available names when there is none, and for a node outside the default scene.
GltfCameraView gltf_camera(const formats::SceneFile& scene, const std::string& name);

// Unit direction of the primary ray through image point (x, y), in pixels from the top-left
// corner of a width x height image (pixel centres at i + 0.5); square pixels. Perspective only.
Vec3 primary_ray_direction(const PinholeCamera& camera, double x, double y, int width, int height);

struct PrimaryRay {
  Vec3 origin, direction;  // direction unit length
};

// The primary ray through image point (x, y) as above, for either projection: from the eye through
// the point (perspective), or from the point on the eye's plane along forward (orthographic).
PrimaryRay primary_ray(const PinholeCamera& camera, double x, double y, int width, int height);

}  // namespace exitance::view
