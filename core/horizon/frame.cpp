#include "core/horizon/frame.h"

namespace aolab {

HorizonFrame horizon_frame(Buffer<float>& depth, const Image& normals, const CameraIntrinsics& cam,
                           float mip_distance, int threads) {
  HorizonFrame f{depth.data(), normals.data(), normals.width(), normals.height(), cam};
  if (mip_distance > 0.0f) {
    f.mip = depth_mip_layout(f.width, f.height, kMaxDepthMipLevel);
    build_depth_mip(depth, f.mip, threads);  // may move the depth
    f.depth = depth.data();
    f.inv_mip_distance = 1.0f / mip_distance;
  }
  return f;
}

}  // namespace aolab
