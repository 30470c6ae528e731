#include "core/io/image_io.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <memory>

#include "core/base/check.h"

namespace aolab {

namespace fs = std::filesystem;
using OIIO::ImageInput;
using OIIO::ImageOutput;
using OIIO::ImageSpec;
using OIIO::TypeDesc;

namespace {

std::string joined(const std::vector<std::string>& names) {
  std::string s = "[";
  for (std::size_t i = 0; i < names.size(); ++i) s += (i ? ", " : "") + names[i];
  return s + "]";
}

std::string lower_extension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

std::unique_ptr<ImageInput> open_input(const std::string& path, const std::string& what_file) {
  require_regular_file(path, what_file);
  auto in = ImageInput::open(path);
  if (!in) throw std::invalid_argument("cannot read " + path + ": " + OIIO::geterror());
  return in;
}

// A Blender pass: the channels <prefix><pass>.<component> for each component.
struct Pass {
  const char* name;
  std::vector<std::string> components;
  std::vector<int> indices;  // channel index of each component; empty if the pass is absent
};

// Finds the channels of `pass`; all or none must be present, a partial pass is an error
// (a hand-edited or truncated file), because guessing the missing component would be wrong.
void locate(const ImageSpec& spec, const std::string& prefix, Pass& pass, const std::string& path) {
  std::vector<int> found;
  std::vector<std::string> missing;
  for (const auto& comp : pass.components) {
    const std::string name = prefix + pass.name + "." + comp;
    const int index = spec.channelindex(name);
    if (index >= 0)
      found.push_back(index);
    else
      missing.push_back(name);
  }
  if (!found.empty() && !missing.empty())
    throw std::invalid_argument(path + ": pass " + prefix + pass.name + " lacks channel(s) " +
                                joined(missing) + "; channels found: " + joined(spec.channelnames));
  pass.indices = missing.empty() ? found : std::vector<int>{};
}

// The prefix ("<layer>." or "") of the view layer to read; see load_gbuffer.
std::string layer_prefix(const ImageSpec& spec, const std::string& view_layer,
                         const std::string& path) {
  const std::string depth = "Depth.Z";
  if (!view_layer.empty()) {
    const std::string prefix = view_layer + ".";
    if (spec.channelindex(prefix + depth) < 0)
      throw std::invalid_argument(path + ": no channel " + prefix + depth + " for view layer \"" +
                                  view_layer + "\"; channels found: " + joined(spec.channelnames));
    return prefix;
  }
  // Layer names may themselves contain dots ("View Layer.001"), so the prefix is everything
  // before the ".Depth.Z" suffix, not the text up to the first dot.
  const std::string suffix = "." + depth;
  for (const auto& name : spec.channelnames) {
    if (name == depth) return "";
    if (name.size() > suffix.size() &&
        name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0)
      return name.substr(0, name.size() - suffix.size() + 1);
  }
  throw std::invalid_argument(path + ": no depth channel (<ViewLayer>.Depth.Z or Depth.Z); " +
                              "channels found: " + joined(spec.channelnames));
}

// n_view = R^T n_world with R the column-normalised upper-left 3x3 of camera_to_world:
// component i of n_view is the dot product of camera axis i (column i) with n_world.
// No renormalisation or flip: prepared_normals() does that, for every source alike.
void world_to_view(Image& normal, const std::array<double, 16>& m) {
  float axis[3][3];
  for (int c = 0; c < 3; ++c) {
    const double len = std::hypot(m[std::size_t(c)], m[std::size_t(4 + c)], m[std::size_t(8 + c)]);
    for (int r = 0; r < 3; ++r) axis[c][r] = float(m[std::size_t(4 * r + c)] / len);
  }
  float* p = normal.data();
  const std::size_t n = std::size_t(normal.width()) * std::size_t(normal.height());
  for (std::size_t i = 0; i < n; ++i, p += 3) {
    const float w[3] = {p[0], p[1], p[2]};
    for (int c = 0; c < 3; ++c) p[c] = axis[c][0] * w[0] + axis[c][1] * w[1] + axis[c][2] * w[2];
  }
}

[[noreturn]] void write_failed(const std::string& path, const std::string& detail) {
  throw std::runtime_error("cannot write " + path + ": " + detail);
}

// Encodes `data` (float or byte pixels with the given strides in bytes) in the format that
// `path`'s extension names, into memory: OpenImageIO converts to the spec's (per-channel)
// formats. The bytes then go to disk through write_file_durably, because an encoder writing
// to a file of its own does not report every failed write (a full disk once left an empty
// EXR behind a successful close).
std::string encode_with_oiio(const std::string& path, const ImageSpec& spec, TypeDesc data_format,
                             const void* data, OIIO::stride_t xstride, OIIO::stride_t ystride) {
  auto out = ImageOutput::create(path);
  if (!out) write_failed(path, OIIO::geterror());
  if (!out->supports("ioproxy")) write_failed(path, "its format cannot be encoded in memory");
  std::vector<unsigned char> buffer;
  OIIO::Filesystem::IOVecOutput proxy(buffer);
  if (!out->set_ioproxy(&proxy)) write_failed(path, out->geterror());
  if (!out->open(path, spec)) write_failed(path, out->geterror());
  if (!out->write_image(data_format, data, xstride, ystride)) {
    const std::string error = out->geterror();
    out->close();
    write_failed(path, error);
  }
  if (!out->close()) write_failed(path, out->geterror());
  return std::string(buffer.begin(), buffer.end());
}

}  // namespace

std::vector<std::string> exr_channel_names(const std::string& path) {
  auto in = open_input(path, "image file");
  return in->spec().channelnames;
}

Image read_image(const std::string& path) {
  auto in = open_input(path, "image file");
  const ImageSpec& spec = in->spec();
  if (spec.deep || spec.depth != 1)
    throw std::invalid_argument(path + ": deep or volume images are not supported");
  Image image(spec.width, spec.height, spec.nchannels);
  if (!in->read_image(0, 0, 0, spec.nchannels, TypeDesc::FLOAT, image.data()))
    throw std::invalid_argument("cannot read the pixels of " + path + ": " + in->geterror());
  return image;
}

GBuffer GBufferData::view() const {
  GBuffer g;
  g.depth = depth.view();
  g.normal = normal.view();  // an empty Image gives an empty view: "absent"
  g.color = color.view();
  g.emission = emission.view();
  g.camera = sidecar.intrinsics();
  g.background_depth = sidecar.background_depth;
  return g;
}

GBufferData load_gbuffer(const std::string& exr_path, const std::string& view_layer) {
  auto in = open_input(exr_path, "EXR file");
  const ImageSpec spec = in->spec();
  GBufferData data;
  data.channels = spec.channelnames;

  if (spec.deep || spec.depth != 1)
    throw std::invalid_argument(exr_path + ": deep or volume images are not G-buffers");
  if (spec.x != spec.full_x || spec.y != spec.full_y || spec.width != spec.full_width ||
      spec.height != spec.full_height)
    throw std::invalid_argument(exr_path +
                                ": its data window differs from its display window "
                                "(cropped border render?); only full frames are supported");

  const std::string prefix = layer_prefix(spec, view_layer, exr_path);
  Pass depth{"Depth", {"Z"}, {}};
  Pass normal{"Normal", {"X", "Y", "Z"}, {}};
  Pass color{"DiffCol", {"R", "G", "B"}, {}};
  Pass emission{"Emit", {"R", "G", "B"}, {}};
  Pass ao{"AO", {"R"}, {}};  // R = G = B in Cycles' AO pass; one is enough
  for (Pass* p : {&depth, &normal, &color, &emission, &ao}) locate(spec, prefix, *p, exr_path);

  // Checked before the pixels are decoded: a mismatched or missing sidecar is the cheap error.
  data.sidecar = read_sidecar(sidecar_path_for(exr_path));
  const CameraSidecar& side = data.sidecar;
  if (side.width != spec.width || side.height != spec.height)
    throw std::invalid_argument("sidecar " + sidecar_path_for(exr_path) + " says " +
                                std::to_string(side.width) + "x" + std::to_string(side.height) +
                                " (width x height) but " + exr_path + " is " +
                                std::to_string(spec.width) + "x" + std::to_string(spec.height));
  const bool world_normals = !normal.indices.empty() && side.normal_space == "world";
  if (world_normals && !side.has_camera_to_world)
    throw std::invalid_argument(
        "sidecar key \"camera_to_world\" in " + sidecar_path_for(exr_path) +
        " is required to turn the world-space normals of " + exr_path +
        " into view space (normal_space is \"world\", the default); got no such key");

  // One read of the channel range spanning every wanted channel: an EXR chunk is
  // decompressed once per read, so one read beats one read per pass.
  int chbegin = spec.nchannels, chend = 0;
  for (const Pass* p : {&depth, &normal, &color, &emission, &ao})
    for (int i : p->indices) {
      chbegin = std::min(chbegin, i);
      chend = std::max(chend, i + 1);
    }
  const int span = chend - chbegin;
  const std::size_t pixels = std::size_t(spec.width) * std::size_t(spec.height);
  std::vector<float> buffer(pixels * std::size_t(span));
  if (!in->read_image(0, 0, chbegin, chend, TypeDesc::FLOAT, buffer.data()))
    throw std::invalid_argument("cannot read the pixels of " + exr_path + ": " + in->geterror());

  auto extract = [&](const Pass& p) {
    if (p.indices.empty()) return Image();
    const int n = int(p.indices.size());
    Image img(spec.width, spec.height, n);
    float* dst = img.data();
    for (std::size_t i = 0; i < pixels; ++i)
      for (int c = 0; c < n; ++c)
        *dst++ = buffer[i * std::size_t(span) + std::size_t(p.indices[std::size_t(c)] - chbegin)];
    return img;
  };
  data.depth = extract(depth);
  data.normal = extract(normal);
  data.color = extract(color);
  data.emission = extract(emission);
  data.ao = extract(ao);
  if (world_normals) world_to_view(data.normal, side.camera_to_world);
  return data;
}

void save_gbuffer(const std::string& exr_path, const GBuffer& g, ConstImageView reference_ao,
                  const std::string& sidecar_json, const std::string& view_layer) {
  g.validate();
  if (!reference_ao.empty()) {
    if (reference_ao.channels != 1)
      throw_invalid("reference", "must have 1 channel (H, W)", reference_ao.channels);
    require_same_size("depth", g.depth, "reference", reference_ao);
  }
  if (lower_extension(exr_path) != ".exr") throw_invalid("path", "must end in .exr", exr_path);
  // Validated in full before anything is written, so a bad sidecar leaves no files behind.
  const std::string sidecar_path = sidecar_path_for(exr_path);
  const std::string sidecar_text = sidecar_json_for(g, sidecar_json);
  parse_sidecar(sidecar_text, sidecar_path);

  // Output channels in Blender's layout: name, format, source image and its channel.
  struct Channel {
    std::string name;
    TypeDesc format;
    ConstImageView source;
    int source_channel;
  };
  const std::string prefix = view_layer.empty() ? "" : view_layer + ".";
  // Depth stays float32: half would round depths (and turn 1e10 background into inf).
  std::vector<Channel> channels{{prefix + "Depth.Z", TypeDesc::FLOAT, g.depth, 0}};
  if (g.has_normal())
    for (int c = 0; c < 3; ++c)
      channels.push_back({prefix + "Normal." + "XYZ"[c], TypeDesc::HALF, g.normal, c});
  if (!reference_ao.empty())
    for (int c = 0; c < 3; ++c)
      channels.push_back({prefix + "AO." + "RGB"[c], TypeDesc::HALF, reference_ao, 0});
  if (g.has_color())
    for (int c = 0; c < 3; ++c)
      channels.push_back({prefix + "DiffCol." + "RGB"[c], TypeDesc::HALF, g.color, c});
  if (g.has_emission())
    for (int c = 0; c < 3; ++c)
      channels.push_back({prefix + "Emit." + "RGB"[c], TypeDesc::HALF, g.emission, c});

  const int w = g.width(), h = g.height(), n = int(channels.size());
  ImageSpec spec(w, h, n, TypeDesc::FLOAT);
  spec.channelnames.clear();
  for (const auto& ch : channels) {
    spec.channelnames.push_back(ch.name);
    spec.channelformats.push_back(ch.format);
  }
  spec.attribute("compression", "zip");  // Blender's default EXR codec
  // Blender marks its multilayer EXRs with this header attribute; writing it too lets
  // Blender open the file as a multilayer image like one of its own renders.
  spec.attribute("BlenderMultiChannel", "Blender V2.55.1 and newer");

  std::vector<float> pixels(std::size_t(w) * std::size_t(h) * std::size_t(n));
  float* dst = pixels.data();
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (const auto& ch : channels) *dst++ = ch.source(x, y, ch.source_channel);

  // The EXR and its sidecar are put in place together: a failure leaves both as they were.
  write_files_durably({{exr_path, encode_with_oiio(exr_path, spec, TypeDesc::FLOAT, pixels.data(),
                                                   OIIO::AutoStride, OIIO::AutoStride)},
                       {sidecar_path, sidecar_file_text(sidecar_text, sidecar_path)}});
}

std::string encode_image(const std::string& path, ConstImageView image) {
  const std::string ext = lower_extension(path);
  if (ext != ".exr" && ext != ".png") throw_invalid("path", "must end in .exr or .png", path);
  if (image.empty())
    throw_invalid("image", "must be a non-empty image",
                  std::to_string(image.width) + "x" + std::to_string(image.height));
  const int nc = image.channels;
  if (nc != 1 && nc != 3 && nc != 4) throw_invalid("image", "must have 1, 3 or 4 channels", nc);

  if (ext == ".exr") {
    ImageSpec spec(image.width, image.height, nc, TypeDesc::FLOAT);
    spec.channelnames = nc == 1   ? std::vector<std::string>{"Y"}
                        : nc == 3 ? std::vector<std::string>{"R", "G", "B"}
                                  : std::vector<std::string>{"R", "G", "B", "A"};
    if (nc == 4) spec.alpha_channel = 3;
    spec.attribute("compression", "zip");
    // The view may be strided (a numpy slice): pass its strides instead of copying.
    const auto xstride = OIIO::stride_t(sizeof(float)) * nc;
    const auto ystride = OIIO::stride_t(sizeof(float)) * image.row_stride;
    return encode_with_oiio(path, spec, TypeDesc::FLOAT, image.data, xstride, ystride);
  }

  // PNG: value·255 rounded, no transfer curve (see the header); NaN has no meaningful
  // byte, 0 makes it visible as black rather than hiding it as white.
  std::vector<std::uint8_t> bytes(image.pixel_count() * std::size_t(nc));
  std::uint8_t* dst = bytes.data();
  for (int y = 0; y < image.height; ++y) {
    const float* src = image.row(y);
    for (int i = 0; i < image.width * nc; ++i) {
      const float v = src[i];
      *dst++ = std::isnan(v) ? 0 : std::uint8_t(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f));
    }
  }
  ImageSpec spec(image.width, image.height, nc, TypeDesc::UINT8);
  if (nc == 4) spec.alpha_channel = 3;
  return encode_with_oiio(path, spec, TypeDesc::UINT8, bytes.data(), OIIO::AutoStride,
                          OIIO::AutoStride);
}

void write_image(const std::string& path, ConstImageView image) {
  write_file_durably(path, encode_image(path, image));
}

}  // namespace aolab
