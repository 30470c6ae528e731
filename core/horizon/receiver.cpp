#include "core/horizon/receiver.h"

namespace aolab {

HorizonReceiver horizon_receiver(const CameraIntrinsics& cam, int x, int y, float depth,
                                 const glm::vec3& normal) {
  HorizonReceiver p;
  p.x = x, p.y = y, p.d = depth, p.n = normal;
  p.px = float(x) + 0.5f, p.py = float(y) + 0.5f;
  p.ox = p.px - cam.cx, p.oy = p.py - cam.cy;
  p.inv_fx = 1.0f / cam.fx, p.inv_fy = 1.0f / cam.fy;
  const glm::vec3 r0(p.ox * p.inv_fx, -p.oy * p.inv_fy, -1.0f);
  p.n_r0 = glm::dot(p.n, r0);
  p.grazing_p = glm::length(r0) / std::abs(p.n_r0);
  return p;
}

}  // namespace aolab
