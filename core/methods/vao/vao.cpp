#include "core/methods/vao/vao.h"

#include <algorithm>
#include <cstdint>

#include "core/base/parallel.h"
#include "core/base/simd_tiles.h"
#include "core/sampling/random.h"
#include "core/volumetric/pipes_simd.h"

namespace aolab {

Image vao(const GBuffer& g, const VaoSettings& s, const RunOptions& options) {
  g.validate();
  require_normal(g, "vao");
  validate_settings(s, kVaoFields);
  const int w = g.width(), h = g.height();
  const int threads = resolve_threads(options.threads);
  const VaoFrame frame = vao_frame(g, false, threads);
  const VaoKernel kernel = vao_spiral_kernel(s.samples);
  VaoPixelOptions po;
  po.radius = s.radius;
  po.view_ray_pipes = s.view_ray_pipes;

  if (options.kernel == Kernel::Simd) {
    VaoSimdSets sets;
    sets.add(kernel);
    sets.random_rotation = s.random_rotation;
    sets.seed = std::uint32_t(s.seed);
    VaoSimdCounts counts;
    counts.samples = s.samples;
    return image_from_simd_tiles(
        w, h, threads, options.progress, [&](int y, int x0, int x1, float* row) {
          vao_simd_span(frame, po, sets, counts, y, x0, x1, 1, 0, row, 1, nullptr);
        });
  }
  Image out(w, h, 1, 1.0f);
  if (options.progress) options.progress->total += h;
  parallel_for_rows(
      h, threads,
      [&](int y0, int y1) {
        VaoKernel scratch;
        for (int y = y0; y < y1; ++y)
          for (int x = 0; x < w; ++x) {
            if (!(frame.depth[std::size_t(y) * w + x] == frame.depth[std::size_t(y) * w + x]))
              continue;  // background: 1
            const VaoKernel* k = &kernel;
            if (s.random_rotation) {
              vao_random_rotation(kernel, std::uint32_t(s.seed), x, y, scratch);
              k = &scratch;
            }
            out(x, y) =
                vao_pixel(frame, po, x, y, k->x.data(), k->y.data(), k->h.data(), k->size()).ao();
          }
      },
      options.progress);
  return out;
}

Method vao_method() {
  Method m = registered_method(
      "vao", "Volumetric ambient occlusion",
      "Szirmay-Kalos, Umenhoffer, Toth, Szecsi, Sbert 2010, Volumetric Ambient Occlusion "
      "for Real-Time Rendering and Games (as outlined in VAO++ 2017, section 3)",
      kVaoFields, vao);
  m.needs_normal = true;
  m.has_simd_kernel = true;
  return m;
}

}  // namespace aolab
