#include "core/io/sidecar.h"

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <system_error>

#include "core/base/check.h"
#include "core/io/files.h"

namespace aolab {

namespace {

// ordered_json keeps the keys in the order the document has them, so a sidecar passed
// through save_gbuffer keeps the layout its writer chose.
using Json = nlohmann::ordered_json;

std::string key_list(const Json& doc) {
  std::string s = "[";
  bool first = true;
  for (const auto& item : doc.items()) {
    s += (first ? "" : ", ") + item.key();
    first = false;
  }
  return s + "]";
}

// Every error about one key goes through here, so all of them name the key and the file.
[[noreturn]] void bad_value(const std::string& source, const std::string& key,
                            const std::string& requirement, const Json& value) {
  throw_invalid("sidecar key \"" + key + "\" in " + source, requirement, value.dump());
}

// nullptr when the key is absent or null: an optional key written as null (what json.dumps
// makes of None) means "not given".
const Json* optional_key(const Json& doc, const char* key) {
  const auto it = doc.find(key);
  if (it == doc.end() || it->is_null()) return nullptr;
  return &*it;
}

const Json& required_key(const Json& doc, const char* key, const std::string& source) {
  const auto it = doc.find(key);
  if (it == doc.end())
    throw_invalid("sidecar " + source, "must have the required key \"" + std::string(key) + "\"",
                  "keys " + key_list(doc));
  // Present but null: say so, rather than calling a key that is there missing.
  if (it->is_null()) bad_value(source, key, "is required and must not be null", *it);
  return *it;
}

// A value that becomes a float in the G-buffer (fx, fy, cx, cy): 1e-50 or 1e300 are valid
// doubles but would round to 0 or infinity there, and then be reported as "got 0" far from
// the file that holds them.
double float_number(double d, const Json& value, const char* key, const std::string& source,
                    bool positive) {
  const float f = float(d);
  if (!std::isfinite(f) || (positive && !(f > 0)))
    bad_value(source, key,
              positive ? "must fit in a float: > 0 and at least 1.4e-45 (the smallest float), "
                         "at most 3.4e38"
                       : "must fit in a float: at most 3.4e38 in magnitude",
              value);
  return d;
}

double finite_number(const Json& value, const char* key, const std::string& source) {
  // JSON booleans are not numbers in nlohmann's model either, so `true` is rejected here.
  if (!value.is_number()) bad_value(source, key, "must be a number", value);
  const double d = value.get<double>();
  if (!std::isfinite(d)) bad_value(source, key, "must be finite", value);
  return d;
}

double positive_number(const Json& value, const char* key, const std::string& source) {
  const double d = finite_number(value, key, source);
  if (!(d > 0)) bad_value(source, key, "must be > 0", value);
  return d;
}

int integer(const Json& value, const char* key, const std::string& source, int min_value) {
  // Strict on purpose: 640.0 for a width means the writer computed it in floating point,
  // which is worth fixing at the source rather than rounding here.
  if (!value.is_number_integer()) bad_value(source, key, "must be an integer", value);
  const bool fits =
      value.is_number_unsigned()
          ? value.get<std::uint64_t>() <= std::uint64_t(std::numeric_limits<int>::max())
          : value.get<std::int64_t>() >= std::numeric_limits<int>::min() &&
                value.get<std::int64_t>() <= std::numeric_limits<int>::max();
  if (!fits) bad_value(source, key, "must fit in a 32-bit integer", value);
  const int i = value.get<int>();
  if (i < min_value) bad_value(source, key, "must be >= " + std::to_string(min_value), value);
  return i;
}

std::array<double, 16> matrix4(const Json& value, const char* key, const std::string& source) {
  const char* shape = "must be a 4x4 matrix as 4 rows of 4 numbers [[...], [...], [...], [...]]";
  if (!value.is_array() || value.size() != 4) bad_value(source, key, shape, value);
  std::array<double, 16> m{};
  for (int r = 0; r < 4; ++r) {
    const Json& row = value[std::size_t(r)];
    if (!row.is_array() || row.size() != 4) bad_value(source, key, shape, value);
    for (int c = 0; c < 4; ++c) {
      const Json& e = row[std::size_t(c)];
      if (!e.is_number() || !std::isfinite(e.get<double>()))
        bad_value(source, key, "must hold finite numbers only", value);
      m[std::size_t(4 * r + c)] = e.get<double>();
    }
  }
  // Normals are rotated with the column-normalised upper-left 3x3 (Blender's
  // matrix_world.to_3x3().normalized()): a zero axis cannot be normalised.
  for (int c = 0; c < 3; ++c) {
    const double len = std::hypot(m[std::size_t(c)], m[std::size_t(4 + c)], m[std::size_t(8 + c)]);
    if (!(len > 0))
      bad_value(source, key, "must have non-zero axis columns in its 3x3 part", value);
  }
  return m;
}

// The first byte of `text` that is not part of well-formed UTF-8, or npos. JSON text is
// UTF-8 (RFC 8259 §8.1); a Latin-1 byte is the usual culprit.
std::size_t invalid_utf8_offset(const std::string& text) {
  const auto byte = [&](std::size_t i) { return static_cast<unsigned char>(text[i]); };
  std::size_t i = 0;
  while (i < text.size()) {
    const unsigned char c = byte(i);
    int extra = 0;
    unsigned min_code = 0;
    unsigned code = 0;
    if (c < 0x80) {
      ++i;
      continue;
    } else if ((c & 0xE0) == 0xC0) {
      extra = 1, min_code = 0x80, code = c & 0x1Fu;
    } else if ((c & 0xF0) == 0xE0) {
      extra = 2, min_code = 0x800, code = c & 0x0Fu;
    } else if ((c & 0xF8) == 0xF0) {
      extra = 3, min_code = 0x10000, code = c & 0x07u;
    } else {
      return i;
    }
    if (i + std::size_t(extra) >= text.size()) return i;  // truncated sequence
    for (int e = 1; e <= extra; ++e) {
      const unsigned char t = byte(i + std::size_t(e));
      if ((t & 0xC0) != 0x80) return i;
      code = (code << 6) | (t & 0x3Fu);
    }
    if (code < min_code || code > 0x10FFFF || (code >= 0xD800 && code <= 0xDFFF)) return i;
    i += std::size_t(extra) + 1;
  }
  return std::string::npos;
}

// Deeper nesting than any sidecar needs (camera_to_world is 3 levels) is refused before
// parsing: Python's json module, which turns the text into GBuffer.sidecar, would fail on
// 100,000 nested '[' with a RecursionError.
constexpr int kMaxNesting = 64;

void require_shallow(const std::string& text, const std::string& source) {
  int depth = 0;
  bool in_string = false, escaped = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (escaped)
        escaped = false;
      else if (c == '\\')
        escaped = true;
      else if (c == '"')
        in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > kMaxNesting)
        throw std::invalid_argument("sidecar " + source + " nests arrays and objects deeper than " +
                                    std::to_string(kMaxNesting) + " levels (at byte " +
                                    std::to_string(i) + "); a camera sidecar needs 3");
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
}

Json parse_json(const std::string& text, const std::string& source) {
  if (const std::size_t at = invalid_utf8_offset(text); at != std::string::npos) {
    char hex[8];
    std::snprintf(hex, sizeof hex, "0x%02X", unsigned(static_cast<unsigned char>(text[at])));
    throw std::invalid_argument("sidecar " + source + " is not UTF-8 text: byte " + hex +
                                " at offset " + std::to_string(at) +
                                " is not valid UTF-8 (JSON must be UTF-8; was the file saved as "
                                "Latin-1 or another 8-bit encoding?)");
  }
  require_shallow(text, source);
  try {
    return Json::parse(text);
  } catch (const Json::exception& e) {
    // parse_error and out_of_range (number overflow, e.g. 1e999): both mean invalid JSON.
    throw std::invalid_argument("sidecar " + source + " is not valid JSON: " + e.what());
  }
}

// The shortest decimal that reads back as the same float: 123.4f is written as 123.4, not
// 123.40000152587891, and still loads as exactly the same float.
double shortest_decimal(float v) {
  char buf[64];
  const auto res = std::to_chars(buf, buf + sizeof buf, v);
  double d = v;
  std::from_chars(buf, res.ptr, d);
  return d;
}

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  if (!in) throw std::invalid_argument("sidecar " + path + " cannot be read");
  return s.str();
}

}  // namespace

std::string sidecar_path_for(const std::string& exr_path) {
  return std::filesystem::path(exr_path).replace_extension(".json").string();
}

CameraSidecar parse_sidecar(const std::string& raw_text, const std::string& source) {
  // A UTF-8 byte order mark (what some Windows editors write) is accepted and dropped: JSON
  // forbids it (RFC 8259 §8.1) and Python's json.loads refuses it.
  const std::string json_text =
      raw_text.rfind("\xEF\xBB\xBF", 0) == 0 ? raw_text.substr(3) : raw_text;
  const Json doc = parse_json(json_text, source);
  if (!doc.is_object())
    throw_invalid("sidecar " + source, "must be a JSON object {...}", std::string(doc.type_name()));

  CameraSidecar s;
  s.width = integer(required_key(doc, "width", source), "width", source, 1);
  s.height = integer(required_key(doc, "height", source), "height", source, 1);
  for (const char* key : {"fx", "fy", "cx", "cy"}) {
    const Json& value = required_key(doc, key, source);
    const bool focal = key[0] == 'f';
    const double d =
        focal ? positive_number(value, key, source) : finite_number(value, key, source);
    (key == std::string("fx")   ? s.fx
     : key == std::string("fy") ? s.fy
     : key == std::string("cx") ? s.cx
                                : s.cy) = float_number(d, value, key, source, focal);
  }
  if (const Json* v = optional_key(doc, "camera_to_world")) {
    s.camera_to_world = matrix4(*v, "camera_to_world", source);
    s.has_camera_to_world = true;
  }
  if (const Json* v = optional_key(doc, "ao_distance"))
    s.ao_distance = positive_number(*v, "ao_distance", source);
  if (const Json* v = optional_key(doc, "samples")) s.samples = integer(*v, "samples", source, 0);
  if (const Json* v = optional_key(doc, "background_depth")) {
    const double d = positive_number(*v, "background_depth", source);
    if (!std::isfinite(float(d)))
      bad_value(source, "background_depth", "must fit in a float (< 3.4e38)", *v);
    s.background_depth = float(d);
  }
  if (const Json* v = optional_key(doc, "normal_space")) {
    if (!v->is_string() || (*v != "view" && *v != "world"))
      bad_value(source, "normal_space", "must be \"view\" or \"world\"", *v);
    s.normal_space = v->get<std::string>();
  }
  s.json_text = json_text;
  return s;
}

CameraSidecar read_sidecar(const std::string& path) {
  require_regular_file(path, "camera sidecar");
  return parse_sidecar(read_text(path), path);
}

std::string sidecar_file_text(const std::string& json_text, const std::string& path) {
  // Refuse to write what read_sidecar would reject: the error belongs to the writer.
  parse_sidecar(json_text, path);
  if (json_text.empty() || json_text.back() != '\n') return json_text + '\n';
  return json_text;
}

void write_sidecar(const std::string& path, const std::string& json_text) {
  write_file_durably(path, sidecar_file_text(json_text, path));
}

std::string sidecar_json_for(const GBuffer& g, const std::string& base_json) {
  Json doc = base_json.empty() ? Json::object() : parse_json(base_json, "given to save_gbuffer");
  if (!doc.is_object())
    throw_invalid("sidecar", "must be a JSON object {...}", std::string(doc.type_name()));
  doc["width"] = g.width();
  doc["height"] = g.height();
  doc["fx"] = shortest_decimal(g.camera.fx);
  doc["fy"] = shortest_decimal(g.camera.fy);
  doc["cx"] = shortest_decimal(g.camera.cx);
  doc["cy"] = shortest_decimal(g.camera.cy);
  doc["background_depth"] = shortest_decimal(g.background_depth);
  doc["normal_space"] = "view";
  return doc.dump(2) + "\n";
}

}  // namespace aolab
