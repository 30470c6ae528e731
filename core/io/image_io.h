// Image files: Blender multilayer EXR G-buffers (read and written), AO images (EXR/PNG).
//
// Principles (the file layouts are in docs/file_formats.md):
// - Passes are found by channel name, never by position: `<ViewLayer>.Depth.Z`,
//   `.Normal.X/Y/Z`, `.AO.R`, `.DiffCol.R/G/B`, as Blender writes them.
// - Row 0 is the top of the image, as OpenImageIO reads it and as AO Lab's pixels count.
// - Normals come out in view space: the sidecar's normal_space says what the file holds.
//   They are not renormalised or flipped here; prepared_normals() does that for the methods.
// - Every write is durable and atomic (core/io/files.h): OpenImageIO encodes into memory and
//   write_file_durably puts the bytes in place, so a full disk, a crash or a concurrent
//   reader never sees half a file, and a failed write never replaces a good one.
// - Errors: aolab::FileNotFound for a missing input file or output directory;
//   std::invalid_argument naming the path for an unreadable or corrupt file, a missing pass
//   (listing the channels found) or a bad argument; std::runtime_error when writing fails.
//
// OpenImageIO stays inside image_io.cpp: this header exposes only AO Lab types.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "core/base/gbuffer.h"
#include "core/base/image.h"
#include "core/io/files.h"
#include "core/io/sidecar.h"

namespace aolab {

/// Names of all channels of the image at `path` (first subimage), in file order.
/// Throws FileNotFound, or std::invalid_argument if the file cannot be read as an image.
std::vector<std::string> exr_channel_names(const std::string& path);

/// A G-buffer read from disk: owns its pixels; view() hands out the core's non-owning GBuffer.
struct GBufferData {
  Image depth;     ///< planar depth d = -z (scene units), 1 channel
  Image normal;    ///< view-space normals, 3 channels, as stored (not renormalised); or empty
  Image color;     ///< diffuse colour (DiffCol pass), 3 channels; or empty
  Image emission;  ///< emitted radiance (Emit pass), 3 channels; or empty
  Image ao;        ///< reference AO (AO.R), 1 channel in [0, 1]; or empty
  CameraSidecar sidecar;
  std::vector<std::string> channels;  ///< every channel name in the EXR, in file order

  /// Views of the images above, with the sidecar's intrinsics and background depth.
  /// Valid while this object lives and is not moved from.
  GBuffer view() const;
};

/// Loads a G-buffer from a Blender multilayer EXR and its camera sidecar
/// (sidecar_path_for(exr_path)).
/// `view_layer` picks the layer by name; "" takes the first layer that has a Depth.Z channel
/// (an un-prefixed "Depth.Z" counts as a layer named ""). Normal, DiffCol, Emit and AO are read
/// when all their channels are present. World-space normals (sidecar normal_space "world") are
/// rotated into view space with camera_to_world: n_view = R^T n_world, R the column-normalised
/// upper-left 3x3.
/// Throws FileNotFound for a missing EXR or sidecar; std::invalid_argument naming the path
/// for an unreadable file, a missing Depth.Z (listing the channels found), a pass with only
/// some of its channels, a sidecar whose width/height differ from the EXR, or world-space
/// normals without camera_to_world.
GBufferData load_gbuffer(const std::string& exr_path, const std::string& view_layer = "");

/// Writes `g` as a Blender-style multilayer EXR at `exr_path` plus its sidecar:
/// `<view_layer>.Depth.Z` float32; `.Normal.X/Y/Z` half (if g has normals); `.AO.R/G/B` half,
/// R = G = B = reference_ao (if not empty; 1 channel, the size of g); `.DiffCol.R/G/B` half
/// (the first 3 colour channels, if g has colour); `.Emit.R/G/B` half (the first 3 emission
/// channels, if g has emission). An empty view_layer writes un-prefixed
/// names ("Depth.Z", ...), which load_gbuffer also reads.
/// The sidecar is `sidecar_json` (a JSON object, "" meaning {}; other keys are kept) with
/// width, height, fx, fy, cx, cy and background_depth set from g and normal_space "view"
/// (g's normals are view-space). So save -> load returns depth exactly and the half channels
/// within half precision (relative 2^-11).
/// Both files are written atomically, the sidecar last, so a sidecar newer than its EXR
/// means the pair is complete.
/// Throws std::invalid_argument for an invalid g (GBuffer::validate), a reference of another
/// size or channel count, a path not ending in .exr, or a sidecar that is not a JSON object
/// or holds an invalid value for a sidecar key;
/// FileNotFound if the directory does not exist; std::runtime_error if writing fails.
void save_gbuffer(const std::string& exr_path, const GBuffer& g, ConstImageView reference_ao,
                  const std::string& sidecar_json, const std::string& view_layer = "ViewLayer");

/// Writes an image (1, 3 or 4 channels, e.g. an AO image) atomically, by extension
/// (case-insensitive):
/// - ".exr": float32, channels "Y" (1 channel) or R, G, B[, A];
/// - ".png": 8-bit, value = round(clamp(v, 0, 1) * 255), NaN -> 0. The values are stored
///   linearly with no transfer curve and no colour tag: AO 0.5 is byte 128, as AO maps are
///   usually shown, not sRGB-encoded.
/// Throws std::invalid_argument for another extension or channel count or an empty image,
/// FileNotFound if the directory does not exist, std::runtime_error if writing fails.
void write_image(const std::string& path, ConstImageView image);

/// The bytes write_image would write to `path` (its extension chooses the format), for
/// callers that put several files in place together (write_files_durably).
std::string encode_image(const std::string& path, ConstImageView image);

/// Reads every channel of the image at `path` (first subimage) as float, row 0 at the top;
/// integer formats are normalised (8-bit PNG byte b reads as b / 255).
/// Throws FileNotFound, or std::invalid_argument if the file cannot be read as an image.
Image read_image(const std::string& path);

}  // namespace aolab
