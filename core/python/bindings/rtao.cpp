// rtao and its ray scene: meshes arrive as numpy arrays, checked at the boundary; the BVH
// build and the ray tracing run with the GIL released.
#include "core/raytracing/rtao.h"

#include <pybind11/stl.h>

#include <limits>
#include <string>

#include "core/base/check.h"
#include "core/python/bindings/numpy_support.h"
#include "core/scenes/analytic_scenes.h"

namespace aolab::python {

namespace {

// An (N, 3) array of real numbers (floats or integers), or a ValueError naming `name`.
py::array checked_rows_of_three(const py::object& value, const std::string& name,
                                const std::string& kinds) {
  if (value.is_none()) throw_invalid(name, "must be an (N, 3) array", "None");
  py::array a = py::module_::import("numpy").attr("asarray")(value);
  if (kinds.find(a.dtype().kind()) == std::string::npos)
    throw_invalid(
        name,
        "must be an (N, 3) array of " + std::string(kinds == "iu" ? "integers" : "real numbers"),
        "dtype " + py::str(a.dtype()).cast<std::string>());
  if (a.ndim() != 2 || a.shape(1) != 3)
    throw_invalid(name, "must be an (N, 3) array", shape_string(a));
  return a;
}

TriangleMesh mesh_from_arrays(const py::object& vertices, const py::object& triangles) {
  TriangleMesh mesh;
  auto v = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(
      checked_rows_of_three(vertices, "vertices", "fiu"));
  mesh.vertices.assign(v.data(), v.data() + v.size());
  // Indices are read as int64 first, so that a negative index or one past 2^32 - 1 is an
  // error rather than a wrapped number.
  auto t = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(
      checked_rows_of_three(triangles, "triangles", "iu"));
  mesh.triangles.resize(std::size_t(t.size()));
  const std::int64_t* src = t.data();
  for (std::size_t k = 0; k < mesh.triangles.size(); ++k) {
    if (src[k] < 0 || src[k] > std::int64_t(std::numeric_limits<std::uint32_t>::max()))
      throw_invalid(
          "triangles",
          "must hold vertex indices in [0, 2^32 - 1] (triangle " + std::to_string(k / 3) + ")",
          src[k]);
    mesh.triangles[k] = std::uint32_t(src[k]);
  }
  return mesh;
}

Matrix4 matrix_from(const py::object& value) {
  py::array a = py::module_::import("numpy").attr("asarray")(value, "float64");
  if (a.ndim() != 2 || a.shape(0) != 4 || a.shape(1) != 4)
    throw_invalid("camera_to_world", "must be a 4x4 matrix", shape_string(a));
  auto m = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
  Matrix4 out;
  std::copy(m.data(), m.data() + 16, out.begin());
  return out;
}

py::dict offset_dict(const RtaoOffset& o) {
  py::dict d;
  d["x"] = o.x, d["y"] = o.y, d["depth"] = o.depth, d["point_distance"] = o.point_distance;
  d["footprint"] = o.footprint, d["scale"] = o.scale, d["epsilon"] = o.epsilon;
  return d;
}

// rtao_range's answer for Python: the counts, the largest offset, and the refusal and
// warning texts (None when there is none).
py::dict range_dict(const RtaoRange& r) {
  py::dict d;
  d["radius"] = r.radius, d["camera_distance"] = r.camera_distance;
  d["longest_edge"] = r.longest_edge, d["coordinate_scale"] = r.coordinate_scale;
  d["pixels"] = r.pixels, d["warned"] = r.warned;
  d["refused"] = r.refused, d["beyond"] = r.beyond;
  d["largest"] = r.pixels ? py::object(offset_dict(r.largest)) : py::object(py::none());
  d["largest_share_of_radius"] = r.pixels ? r.largest.epsilon / r.radius : 0.0;
  const std::string refusal = r.refusal(), warning = r.warning();
  d["refusal"] = refusal.empty() ? py::object(py::none()) : py::object(py::str(refusal));
  d["warning"] = warning.empty() ? py::object(py::none()) : py::object(py::str(warning));
  return d;
}

}  // namespace

void bind_rtao(py::module_& m) {
  py::class_<RayScene>(m, "RayScene", py::dynamic_attr(), R"doc(
The scene's triangles in a G-buffer's view space, in an Embree BVH (built once, shared by
every rtao call on that camera).

RayScene(vertices, triangles, camera_to_world, threads=0): vertices (V, 3) world-space
positions, triangles (T, 3) vertex indices, camera_to_world the sidecar's 4x4 row-major
camera matrix (rotation and translation). Malformed input is a ValueError naming it.
aolab.ray_scene also records where the mesh came from (mesh_source: its .mesh.json and
path), so that aolab.rtao checks it against the G-buffer it traces.
)doc")
      .def(py::init([](const py::object& vertices, const py::object& triangles,
                       const py::object& camera_to_world, int threads) {
             TriangleMesh mesh = mesh_from_arrays(vertices, triangles);
             const Matrix4 c2w = matrix_from(camera_to_world);
             py::gil_scoped_release release;
             return RayScene(mesh, c2w, threads);
           }),
           py::arg("vertices"), py::arg("triangles"), py::arg("camera_to_world"), py::kw_only(),
           py::arg("threads") = 0)
      .def_property_readonly("triangles", &RayScene::triangle_count)
      .def_property_readonly("build_seconds", &RayScene::build_seconds,
                             "wall-clock seconds of the BVH build")
      .def_property_readonly("coordinate_scale", &RayScene::coordinate_scale,
                             "L: the largest distance of a vertex from the world origin or the "
                             "camera")
      .def_property_readonly("camera_distance", &RayScene::camera_distance,
                             "|c|: the camera's distance from the world origin")
      .def_property_readonly("longest_edge", &RayScene::longest_edge,
                             "D: the longest triangle edge (with L and |c|, the scale of the "
                             "float rounding of the triangles near a point: docs/methods/rtao.md)");

  m.def(
      "rtao",
      [](const PyGBuffer& g, const RayScene& scene, const py::dict& settings, int threads,
         Progress* progress) {
        const std::vector<SettingDescription> described = rtao_setting_descriptions();
        const SettingValues values = to_setting_values(settings, described);
        if (!values.count("radius")) throw_invalid("radius", "is required", "nothing");
        const RtaoSettings s = settings_from_values(values, kRtaoFields, "rtao", {});
        RunOptions options{threads, progress};
        Image ao;
        RtaoRange range;
        {
          py::gil_scoped_release release;
          ao = rtao(g.view, scene, s, options, &range);
        }
        return py::make_tuple(to_numpy(std::move(ao)), range_dict(range));
      },
      py::arg("gbuffer"), py::arg("scene"), py::arg("settings"), py::kw_only(),
      py::arg("threads") = 0, py::arg("progress") = nullptr);

  m.def(
      "check_camera_to_world",
      [](const py::object& camera_to_world) {
        check_camera_to_world(matrix_from(camera_to_world));
      },
      py::arg("camera_to_world"),
      "ValueError unless the 4x4 row-major matrix is a rotation and a translation: the rule "
      "of RayScene and of the Blender bridge (core/raytracing/ray_scene.h)");

  m.def(
      "rtao_range",
      [](const PyGBuffer& g, const RayScene& scene, float radius, int threads) {
        RtaoRange range;
        {
          py::gil_scoped_release release;
          range = rtao_range(g.view, scene, radius, threads);
        }
        return range_dict(range);
      },
      py::arg("gbuffer"), py::arg("scene"), py::arg("radius"), py::kw_only(),
      py::arg("threads") = 0);

  // The ray tracer's coordinate bound, so that the bridge holds cameras to the same number.
  m.attr("MAX_RAY_COORDINATE") = double(kMaxRayCoordinate);
  m.def("rtao_settings", [] { return describe_settings_for_python(rtao_setting_descriptions()); });

  // The built-in analytic scenes as world-space triangles (tests of rtao's known answers).
  m.def(
      "analytic_scene_mesh",
      [](const std::string& name, const py::dict& params, double extent) {
        const SettingValues values = to_setting_values(params);
        const TriangleMesh mesh =
            analytic_scene_mesh(analytic_scene_geometry(name, values), extent);
        py::array_t<float> v({py::ssize_t(mesh.vertex_count()), py::ssize_t(3)});
        std::copy(mesh.vertices.begin(), mesh.vertices.end(), v.mutable_data());
        py::array_t<std::uint32_t> t({py::ssize_t(mesh.triangle_count()), py::ssize_t(3)});
        std::copy(mesh.triangles.begin(), mesh.triangles.end(), t.mutable_data());
        return py::make_tuple(v, t);
      },
      py::arg("name"), py::arg("params"), py::arg("extent"));
}

}  // namespace aolab::python
