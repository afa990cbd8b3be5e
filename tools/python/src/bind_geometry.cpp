// Meshes, limit surfaces and regions for Python: elastic.Mesh, load_mesh/save_mesh,
// elastic.Surface (evaluation, curvature and closest points at arrays of points), elastic.Region
// and elastic.image_source.
#include <pybind11/stl.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Geometry>

#include "arrays.h"
#include "elastic/mesh/mesh_io.h"
#include "elastic/mesh/mesh_validation.h"
#include "elastic/regions/image_source.h"
#include "elastic/regions/region_spec.h"
#include "session.h"

namespace elastic::python {

namespace {

// A read-only (V, 3) view of the mesh's positions that keeps `owner` alive (no copy).
py::array positions_view(const std::shared_ptr<PolygonMesh>& mesh, const py::object& owner) {
  py::array view(
      py::dtype::of<double>(), {static_cast<py::ssize_t>(mesh->positions.size()), py::ssize_t{3}},
      {static_cast<py::ssize_t>(sizeof(Eigen::Vector3d)), static_cast<py::ssize_t>(sizeof(double))},
      mesh->positions.empty() ? nullptr : mesh->positions.front().data(), owner);
  view.attr("setflags")(py::arg("write") = false);
  return view;
}

// Adds one face after checking its size and vertex indices.
void add_checked_face(PolygonMesh& mesh, const std::vector<int>& face, py::ssize_t i) {
  if (face.size() < 3) {
    throw py::value_error("faces: face " + std::to_string(i) + " has " +
                          std::to_string(face.size()) + " corners, fewer than 3");
  }
  for (const int index : face) {
    if (index < 0 || index >= mesh.num_vertices()) {
      throw py::value_error("faces: vertex index " + std::to_string(index) + " of face " +
                            std::to_string(i) + " is out of range [0, " +
                            std::to_string(mesh.num_vertices()) + ")");
    }
  }
  mesh.add_face(face);
}

// A mesh from (V, 3) positions and faces: an (F, k) integer array, or a sequence of faces of any
// sizes (mixed polygons).
std::shared_ptr<PolygonMesh> mesh_from_arrays(const py::handle& vertices, const py::handle& faces) {
  const Float64Array v = float_rows(vertices, "vertices", 3);
  auto mesh = std::make_shared<PolygonMesh>();
  const auto span = as_vectors(v);
  mesh->positions.assign(span.begin(), span.end());
  const py::array array = py::array::ensure(faces);
  if (array && array.ndim() == 2) {
    const Int32Array f = int_rows(array, "faces", static_cast<int>(array.shape(1)));
    const auto rows = f.unchecked<2>();
    std::vector<int> face(static_cast<std::size_t>(f.shape(1)));
    for (py::ssize_t i = 0; i < f.shape(0); ++i) {
      for (py::ssize_t k = 0; k < f.shape(1); ++k) {
        face[static_cast<std::size_t>(k)] = rows(i, k);
      }
      add_checked_face(*mesh, face, i);
    }
    return mesh;
  }
  if (!py::isinstance<py::sequence>(faces) || py::isinstance<py::str>(faces)) {
    throw py::value_error(
        "faces: expected an integer array of shape (F, k), k >= 3, or a "
        "sequence of faces");
  }
  py::ssize_t i = 0;
  for (const py::handle item : faces) {
    const Int32Array f = int_rows(item, "faces", 0);
    add_checked_face(*mesh, std::vector<int>(f.data(), f.data() + f.shape(0)), i++);
  }
  return mesh;
}

py::object faces_array(const PolygonMesh& mesh) {
  const int nf = mesh.num_faces();
  if (nf == 0) {
    return new_ints(0, 3);
  }
  const int k = mesh.face_size(0);
  for (int f = 1; f < nf; ++f) {
    if (mesh.face_size(f) != k) {
      return py::none();  // mixed polygon sizes: face_offsets / face_vertices
    }
  }
  Int32Array out = new_ints(nf, k);
  std::copy(mesh.face_vertices.begin(), mesh.face_vertices.end(), out.mutable_data());
  return out;
}

// A mesh file read while Ctrl-C is watched (run_interruptible).
std::shared_ptr<PolygonMesh> read_mesh_interruptible(const std::string& path) {
  auto mesh = std::make_shared<PolygonMesh>();
  run_interruptible([mesh, path] { *mesh = read_mesh(path).mesh; });
  return mesh;
}

SubdivisionScheme parse_scheme(const std::string& scheme) {
  if (scheme == "auto") {
    return SubdivisionScheme::Automatic;
  }
  if (scheme == "loop") {
    return SubdivisionScheme::Loop;
  }
  if (scheme == "catmull-clark") {
    return SubdivisionScheme::CatmullClark;
  }
  throw py::value_error("scheme: expected 'auto', 'loop' or 'catmull-clark', got '" + scheme + "'");
}

std::shared_ptr<SurfaceState> make_surface(std::shared_ptr<PolygonMesh> mesh, std::string name,
                                           const std::string& scheme, bool repair) {
  auto state = std::make_shared<SurfaceState>();
  state->name = std::move(name);
  LimitSurfaceOptions options;
  options.name = state->name;
  options.scheme = parse_scheme(scheme);
  state->mesh = std::move(mesh);
  run_interruptible([state, options, repair] {
    if (repair) {
      sanitize_mesh(*state->mesh, state->name);
    } else {
      require_valid_manifold(*state->mesh, state->name);
    }
    state->surface = std::make_unique<LimitSurface>(*state->mesh, options);
    state->projector = std::make_unique<SurfaceProjector>(*state->surface);
  });
  return state;
}

void check_faces(const SurfaceState& s, const std::vector<SurfacePoint>& points) {
  const int nf = s.surface->num_faces();
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (points[i].face < 0 || points[i].face >= nf) {
      throw py::value_error("face: entry " + std::to_string(i) + " is " +
                            std::to_string(points[i].face) +
                            ", outside the surface's ptex faces [0, " + std::to_string(nf) + ")");
    }
  }
}

template <typename Body>
void parallel(std::size_t n, const Body& body) {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 256),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i != r.end(); ++i) {
                        body(i);
                      }
                    });
}

py::dict evaluate(const SurfaceState& s, const py::handle& face, const py::handle& uv) {
  const std::vector<SurfacePoint> points = surface_points(face, uv);
  check_faces(s, points);
  const auto n = static_cast<py::ssize_t>(points.size());
  Float64Array position = new_rows(n, 3), du = new_rows(n, 3), dv = new_rows(n, 3),
               normal = new_rows(n, 3);
  auto* p = reinterpret_cast<Eigen::Vector3d*>(position.mutable_data());
  auto* a = reinterpret_cast<Eigen::Vector3d*>(du.mutable_data());
  auto* b = reinterpret_cast<Eigen::Vector3d*>(dv.mutable_data());
  auto* nn = reinterpret_cast<Eigen::Vector3d*>(normal.mutable_data());
  {
    const py::gil_scoped_release release;
    parallel(points.size(), [&](std::size_t i) {
      const SurfaceDerivatives d = s.surface->derivatives(points[i]);
      p[i] = d.position;
      a[i] = d.du;
      b[i] = d.dv;
      const Eigen::Vector3d c = d.du.cross(d.dv);
      nn[i] =
          c.norm() > 0.0 ? Eigen::Vector3d(c.normalized()) : s.surface->curvature(points[i]).normal;
    });
  }
  py::dict out;
  out["position"] = position;
  out["du"] = du;
  out["dv"] = dv;
  out["normal"] = normal;
  return out;
}

py::dict curvature(const SurfaceState& s, const py::handle& face, const py::handle& uv) {
  const std::vector<SurfacePoint> points = surface_points(face, uv);
  check_faces(s, points);
  const auto n = static_cast<py::ssize_t>(points.size());
  Float64Array k1 = new_rows(n, 0), k2 = new_rows(n, 0), mean = new_rows(n, 0),
               gaussian = new_rows(n, 0), normal = new_rows(n, 3), dir1 = new_rows(n, 3),
               dir2 = new_rows(n, 3);
  double* k1p = k1.mutable_data();
  double* k2p = k2.mutable_data();
  double* hp = mean.mutable_data();
  double* kp = gaussian.mutable_data();
  auto* np = reinterpret_cast<Eigen::Vector3d*>(normal.mutable_data());
  auto* d1 = reinterpret_cast<Eigen::Vector3d*>(dir1.mutable_data());
  auto* d2 = reinterpret_cast<Eigen::Vector3d*>(dir2.mutable_data());
  {
    const py::gil_scoped_release release;
    parallel(points.size(), [&](std::size_t i) {
      const SurfaceCurvature c = s.surface->curvature(points[i]);
      k1p[i] = c.k1;
      k2p[i] = c.k2;
      hp[i] = c.mean;
      kp[i] = c.gaussian;
      np[i] = c.normal;
      d1[i] = c.dir1;
      d2[i] = c.dir2;
    });
  }
  py::dict out;
  out["k1"] = k1;
  out["k2"] = k2;
  out["mean"] = mean;
  out["gaussian"] = gaussian;
  out["normal"] = normal;
  out["dir1"] = dir1;
  out["dir2"] = dir2;
  return out;
}

py::dict closest(const SurfaceState& s, const py::handle& points) {
  const Float64Array x = float_rows(points, "points", 3);
  const auto queries = as_vectors(x);
  std::vector<ClosestPoint> found(queries.size());
  {
    const py::gil_scoped_release release;
    s.projector->closest(queries, found);
  }
  const auto n = static_cast<py::ssize_t>(found.size());
  std::vector<SurfacePoint> where(found.size());
  Float64Array position = new_rows(n, 3), normal = new_rows(n, 3), distance = new_rows(n, 0);
  auto* p = reinterpret_cast<Eigen::Vector3d*>(position.mutable_data());
  auto* nn = reinterpret_cast<Eigen::Vector3d*>(normal.mutable_data());
  double* d = distance.mutable_data();
  for (std::size_t i = 0; i < found.size(); ++i) {
    where[i] = found[i].point;
    p[i] = found[i].position;
    nn[i] = found[i].normal;
    d[i] = found[i].distance;
  }
  py::dict out = points_dict(where);
  out["position"] = position;
  out["normal"] = normal;
  out["distance"] = distance;
  return out;
}

std::shared_ptr<RegionState> make_region_state(const std::shared_ptr<SurfaceState>& s,
                                               const py::object& spec, const py::object& anchor,
                                               const std::string& name, double max_point_distance) {
  RegionSpec parsed;
  if (py::isinstance<py::str>(spec)) {
    parsed = parse_region_spec(spec.cast<std::string>(), name);
  } else {
    const Float64Array polyline = float_rows(spec, "spec", 3);
    const auto points = as_vectors(polyline);
    parsed.kind = RegionSpec::Kind::Points;
    parsed.points.assign(points.begin(), points.end());
    parsed.text = "points (" + std::to_string(points.size()) + " from an array)";
  }
  if (!anchor.is_none()) {
    const Float64Array a = float_rows(anchor, "anchor", 0);
    if (a.shape(0) != 3) {
      throw py::value_error("anchor: expected 3 coordinates, got " + std::to_string(a.shape(0)));
    }
    parsed.anchor = Eigen::Vector3d(a.at(0), a.at(1), a.at(2));
  }
  auto state = std::make_shared<RegionState>();
  state->surface = s;
  run_interruptible([state, s, parsed, max_point_distance, name] {
    state->region = make_region(*s->projector, parsed,
                                {.max_point_distance = max_point_distance, .name = name});
  });
  return state;
}

}  // namespace

void bind_geometry(py::module_& m) {
  py::class_<PolygonMesh, std::shared_ptr<PolygonMesh>>(
      m, "Mesh",
      "A polygon mesh (the control mesh of a limit surface). vertices: (V, 3) float64, read-only "
      "view; faces: (F, k) int32 when every face has k corners, else None (see face_offsets and "
      "face_vertices).")
      .def(py::init(&mesh_from_arrays), py::arg("vertices"), py::arg("faces"),
           "A mesh from a (V, 3) float64 array of positions and an (F, k) integer array of "
           "counter-clockwise faces (k >= 3), or a sequence of faces of any sizes.")
      .def_property_readonly(
          "vertices",
          [](const std::shared_ptr<PolygonMesh>& self) {
            return positions_view(self, py::cast(self));
          },
          "(V, 3) float64 positions (a read-only view, no copy).")
      .def_property_readonly("faces", &faces_array,
                             "(F, k) int32 corners, or None for mixed sizes.")
      .def_property_readonly(
          "face_offsets",
          [](const PolygonMesh& self) {
            Int32Array out = new_ints(static_cast<py::ssize_t>(self.face_offsets.size()));
            std::copy(self.face_offsets.begin(), self.face_offsets.end(), out.mutable_data());
            return out;
          },
          "(F + 1,) int32: face f's corners are face_vertices[face_offsets[f]:face_offsets[f+1]].")
      .def_property_readonly(
          "face_vertices",
          [](const PolygonMesh& self) {
            Int32Array out = new_ints(static_cast<py::ssize_t>(self.face_vertices.size()));
            std::copy(self.face_vertices.begin(), self.face_vertices.end(), out.mutable_data());
            return out;
          },
          "int32 vertex index of every face corner, faces one after the other.")
      .def_property_readonly("num_vertices", &PolygonMesh::num_vertices,
                             "V, the number of vertices.")
      .def_property_readonly("num_faces", &PolygonMesh::num_faces, "F, the number of faces.")
      .def("__repr__", [](const PolygonMesh& self) {
        return "<elastic.Mesh " + std::to_string(self.num_vertices()) + " vertices, " +
               std::to_string(self.num_faces()) + " faces>";
      });

  m.def(
      "load_mesh", [](const std::string& path) { return read_mesh_interruptible(path); },
      py::arg("path"),
      "Reads an OBJ, OFF, PLY or STL file (by its extension). Raises IoError / InvalidInputError "
      "naming the file.");
  m.def(
      "save_mesh",
      [](const std::string& path, const PolygonMesh& mesh) {
        const py::gil_scoped_release release;
        write_mesh(path, mesh);
      },
      py::arg("path"), py::arg("mesh"),
      "Writes a mesh (format from the extension), atomically: a failed write leaves no partial "
      "file.");

  py::class_<SurfaceState, std::shared_ptr<SurfaceState>>(
      m, "Surface",
      "The limit surface of a control mesh (OpenSubdiv: Loop for triangle meshes, Catmull-Clark "
      "otherwise) with its closest-point search. A surface point is (face, uv): a ptex face index "
      "and parameters in it (docs/python.md).")
      .def(py::init([](const py::object& mesh, const std::string& scheme, bool repair) {
             if (py::isinstance<py::str>(mesh)) {
               const std::string path = mesh.cast<std::string>();
               return make_surface(read_mesh_interruptible(path), path, scheme, repair);
             }
             // The surface keeps its own copy: repairs never change the caller's mesh.
             return make_surface(std::make_shared<PolygonMesh>(mesh.cast<const PolygonMesh&>()),
                                 "mesh", scheme, repair);
           }),
           py::arg("mesh"), py::arg("scheme") = "auto", py::arg("repair") = true,
           "From a Mesh or a file path. scheme: 'auto', 'loop' or 'catmull-clark'. repair: fix "
           "what is safely repairable (as the CLI does), else refuse any defect.")
      .def_property_readonly(
          "mesh", [](const SurfaceState& s) { return s.mesh; }, "The (repaired) control mesh.")
      .def_property_readonly(
          "num_faces", [](const SurfaceState& s) { return s.surface->num_faces(); },
          "Number of ptex faces (valid face values are 0 .. num_faces - 1).")
      .def_property_readonly(
          "scheme",
          [](const SurfaceState& s) {
            return s.surface->scheme() == SubdivisionScheme::Loop ? "loop" : "catmull-clark";
          },
          "'loop' or 'catmull-clark'.")
      .def_property_readonly(
          "name", [](const SurfaceState& s) { return s.name; }, "The name used in messages.")
      .def(
          "evaluate",
          [](const SurfaceState& s, const py::handle& f, const py::handle& uv) {
            return evaluate(s, f, uv);
          },
          py::arg("face"), py::arg("uv"),
          "Positions, first derivatives and unit normals at surface points (face: (N,) int32, uv: "
          "(N, 2) float64) -> dict of (N, 3) arrays 'position', 'du', 'dv', 'normal'.")
      .def(
          "curvature",
          [](const SurfaceState& s, const py::handle& f, const py::handle& uv) {
            return curvature(s, f, uv);
          },
          py::arg("face"), py::arg("uv"),
          "Principal curvatures at surface points -> dict: 'k1' >= 'k2', 'mean', 'gaussian' (N,) "
          "and 'normal', 'dir1', 'dir2' (N, 3).")
      .def(
          "closest",
          [](const SurfaceState& s, const py::handle& points) { return closest(s, points); },
          py::arg("points"),
          "Closest limit-surface points to (N, 3) float64 points -> dict: 'face' (N,) int32, "
          "'uv' (N, 2), 'position' (N, 3), 'normal' (N, 3), 'distance' (N,).")
      .def(
          "region",
          [](const std::shared_ptr<SurfaceState>& s, const py::object& spec,
             const py::object& anchor, const std::string& name, double max_point_distance) {
            return make_region_state(s, spec, anchor, name, max_point_distance);
          },
          py::arg("spec"), py::arg("anchor") = py::none(), py::arg("name") = "region",
          py::arg("max_point_distance") = 0.05,
          "A region with a closed boundary curve: a spec string as the CLI's --source-region / "
          "--target-region ('boundary', 'disk:X,Y,Z,R', 'points:...', 'uv:...'), or an (N, 3) "
          "float64 polyline of points near the surface (joined by shortest paths). anchor: a "
          "point near the boundary where the correspondence starts.")
      .def("__repr__", [](const SurfaceState& s) {
        return "<elastic.Surface '" + s.name + "' " + std::to_string(s.surface->num_faces()) +
               " ptex faces>";
      });

  py::class_<RegionState, std::shared_ptr<RegionState>>(
      m, "Region", "A disk-like region of a surface, bounded by one closed curve.")
      .def_property_readonly(
          "area", [](const RegionState& r) { return r.region.area(); }, "Area of its triangles.")
      .def_property_readonly(
          "positions", [](const RegionState& r) { return rows_of(std::span(r.region.positions)); },
          "(V, 3) float64 limit positions of the region's tessellation.")
      .def_property_readonly(
          "triangles", [](const RegionState& r) { return triangles_of(r.region.triangles); },
          "(T, 3) int32 counter-clockwise triangles.")
      .def_property_readonly(
          "points", [](const RegionState& r) { return points_dict(r.region.points); },
          "The vertices as surface points: dict 'face' (V,), 'uv' (V, 2).")
      .def_property_readonly(
          "boundary",
          [](const RegionState& r) {
            Int32Array out = new_ints(static_cast<py::ssize_t>(r.region.boundary.size()));
            std::copy(r.region.boundary.begin(), r.region.boundary.end(), out.mutable_data());
            return out;
          },
          "(B,) int32 vertex indices of the boundary loop, counter-clockwise.")
      .def_property_readonly(
          "surface",
          [](const RegionState& r) { return std::const_pointer_cast<SurfaceState>(r.surface); },
          "The surface it lies on.")
      .def("__repr__", [](const RegionState& r) {
        return "<elastic.Region " + std::to_string(r.region.num_triangles()) + " triangles, area " +
               std::to_string(r.region.area()) + ">";
      });

  m.def(
      "image_source",
      [](const std::string& path, double width, const std::string& shape, std::int64_t max_pixels) {
        if (max_pixels <= 0) {
          throw py::value_error("max_pixels: expected a positive count, got " +
                                std::to_string(max_pixels));
        }
        if (shape != "rectangle" && shape != "ellipse") {
          throw py::value_error("shape: expected 'rectangle' or 'ellipse', got '" + shape + "'");
        }
        auto plane = std::make_shared<ImagePlane>();
        const ImagePlaneOptions options{
            .width = width,
            .shape = shape == "ellipse" ? ImageRegionShape::Ellipse : ImageRegionShape::Rectangle};
        const ImageReadOptions read{.max_pixels = max_pixels, .limit_name = "max_pixels"};
        run_interruptible(
            [plane, path, options, read] { *plane = make_image_plane(path, options, read); });
        auto surface = make_surface(std::make_shared<PolygonMesh>(plane->mesh), path, "auto", true);
        auto region = std::make_shared<RegionState>();
        region->surface = surface;
        run_interruptible([region, surface, plane] {
          region->region =
              make_region(*surface->projector, plane->region, {.name = "source region"});
        });
        return py::make_tuple(surface, region);
      },
      py::arg("path"), py::arg("width") = 2.0, py::arg("shape") = "rectangle",
      py::arg("max_pixels") = kDefaultMaxImagePixels,
      "A source made from an image (as the CLI's --source-image): the plane carrying it, `width` "
      "wide (--image-width), and its region ('rectangle' or the inscribed 'ellipse') -> (Surface, "
      "Region). Images of more than max_pixels pixels (--max-image-pixels) are refused from their "
      "header, before decoding.");
}

}  // namespace elastic::python
