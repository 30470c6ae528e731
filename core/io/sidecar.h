// The camera sidecar: a JSON document beside each G-buffer EXR (scene.exr -> scene.json)
// holding what an EXR cannot say by itself — the intrinsics in AO Lab's convention, the
// camera pose (needed to turn Blender's world-space normals into view space), the reference's
// AO distance and sample count. Only the keys below are interpreted; every other key (clip
// range, render settings, hashes written by the Blender bridge) is carried along untouched
// in json_text. The schema is documented in docs/file_formats.md.
//
// Errors: std::invalid_argument naming the key and the file (missing required key, wrong
// type, non-finite or out-of-range value, invalid JSON with the parser's message);
// aolab::FileNotFound (core/io/files.h) when the file does not exist.
#pragma once

#include <array>
#include <limits>
#include <string>

#include "core/base/camera.h"
#include "core/base/gbuffer.h"

namespace aolab {

/// The interpreted part of a sidecar document, plus the whole document.
struct CameraSidecar {
  int width = 0;   ///< image width in pixels, > 0 (required; must match the EXR)
  int height = 0;  ///< image height in pixels, > 0 (required; must match the EXR)
  double fx = 0;   ///< focal length along x in pixels, > 0 (required)
  double fy = 0;   ///< focal length along y in pixels, > 0 (required)
  double cx = 0;   ///< principal point, pixels from the left edge (required)
  double cy = 0;   ///< principal point, pixels from the top edge (required)
  /// Camera-to-world matrix, row-major (element [r][c] at index 4r + c), as Blender's
  /// `cam.matrix_world`. Optional; identity when absent (then has_camera_to_world is false).
  std::array<double, 16> camera_to_world{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  bool has_camera_to_world = false;
  /// The reference's AO distance (world units, > 0) — the radius R to compare at.
  /// Optional; NaN when absent.
  double ao_distance = std::numeric_limits<double>::quiet_NaN();
  int samples = 0;  ///< samples per pixel of the reference AO, >= 0; 0 when absent/unknown
  /// Depth at or above this is background (> 0). Optional; kDefaultBackgroundDepth if absent.
  float background_depth = kDefaultBackgroundDepth;
  /// Space of the EXR's Normal pass: "view" or "world". Optional; "world" when absent,
  /// because that is what Blender's Normal pass stores. Converting "world" normals needs
  /// camera_to_world.
  std::string normal_space = "world";
  /// The whole document as read (or to be written), including keys not interpreted here.
  std::string json_text;

  /// fx, fy, cx, cy as the camera the methods use.
  CameraIntrinsics intrinsics() const { return {float(fx), float(fy), float(cx), float(cy)}; }
};

/// The sidecar path of an EXR: same directory and stem, extension ".json"
/// ("renders/scene.exr" -> "renders/scene.json").
std::string sidecar_path_for(const std::string& exr_path);

/// Reads and validates the sidecar at `path`.
/// Throws aolab::FileNotFound if it does not exist, std::invalid_argument naming the key and
/// the file for invalid JSON, a document that is not an object, a missing required key, a
/// value of the wrong type, non-finite or out of range, or an unknown normal_space.
CameraSidecar read_sidecar(const std::string& path);

/// Parses and validates sidecar text; `source` names the document in error messages
/// (normally its path). Same errors as read_sidecar.
CameraSidecar parse_sidecar(const std::string& json_text, const std::string& source);

/// The bytes of a sidecar file: `json_text`, which must be a valid sidecar (parse_sidecar's
/// checks, naming `path`), ending in a newline.
std::string sidecar_file_text(const std::string& json_text, const std::string& path);

/// Writes `json_text` (which must be a JSON object) to `path` durably and atomically
/// (write_file_durably, core/io/files.h): readers see either the old file or the complete
/// new one. Throws std::invalid_argument if the text is
/// not a JSON object, aolab::FileNotFound if the directory does not exist,
/// std::runtime_error if writing fails (the temporary file is removed).
void write_sidecar(const std::string& path, const std::string& json_text);

/// The sidecar text save_gbuffer writes for `g`: `base_json` (a JSON object, "" meaning {};
/// its other keys kept in their order) with width, height, fx, fy, cx, cy, background_depth
/// taken from g — each float written as its shortest decimal, which reads back as the same
/// float — and normal_space "view". Throws std::invalid_argument if base_json is not a JSON
/// object.
std::string sidecar_json_for(const GBuffer& g, const std::string& base_json);

}  // namespace aolab
