#include "arrays.h"

#include <limits>
#include <sstream>

namespace elastic::python {

std::string shape_text(const py::array& array) {
  std::ostringstream text;
  text << '(';
  for (py::ssize_t d = 0; d < array.ndim(); ++d) {
    text << (d ? ", " : "") << array.shape(d);
  }
  text << (array.ndim() == 1 ? ",)" : ")");
  return text.str();
}

namespace {

std::string expected_shape(int columns) {
  return columns == 0 ? "(N,)" : "(N, " + std::to_string(columns) + ")";
}

void check_shape(const py::array& array, const char* name, int columns, const char* dtype) {
  const bool ok = columns == 0
                      ? array.ndim() == 1
                      : array.ndim() == 2 && array.shape(1) == static_cast<py::ssize_t>(columns);
  if (!ok) {
    throw py::value_error(std::string(name) + ": expected a " + dtype + " array of shape " +
                          expected_shape(columns) + ", got shape " + shape_text(array));
  }
}

// The dtype's kind ('f', 'i', 'u', ...), read as a Python attribute.
char dtype_kind(const py::array& array) {
  return array.dtype().attr("kind").cast<std::string>().at(0);
}

}  // namespace

Float64Array float_rows(const py::handle& object, const char* name, int columns) {
  const py::array array = py::array::ensure(object);
  if (!array) {
    throw py::value_error(std::string(name) + ": expected a float64 array of shape " +
                          expected_shape(columns) + ", got " +
                          std::string(py::str(py::type::of(object).attr("__name__"))));
  }
  const char kind = dtype_kind(array);
  if (kind != 'f' && kind != 'i' && kind != 'u') {
    throw py::value_error(std::string(name) + ": expected a float64 array, got dtype " +
                          std::string(py::str(array.dtype())));
  }
  check_shape(array, name, columns, "float64");
  Float64Array out = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(array);
  if (!out) {
    throw py::error_already_set();
  }
  return out;
}

Int32Array int_rows(const py::handle& object, const char* name, int columns) {
  const py::array array = py::array::ensure(object);
  if (!array || (dtype_kind(array) != 'i' && dtype_kind(array) != 'u')) {
    throw py::value_error(std::string(name) + ": expected an integer array of shape " +
                          expected_shape(columns) +
                          (array ? ", got dtype " + std::string(py::str(array.dtype())) : ""));
  }
  check_shape(array, name, columns, "int32");
  if (array.dtype().is(py::dtype::of<std::int32_t>()) && (array.flags() & py::array::c_style)) {
    return Int32Array::ensure(array);  // a view, no copy
  }
  // Other integer widths: every value must fit int32 (no silent wrap-around).
  const auto wide =
      py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(array);
  if (!wide) {
    throw py::error_already_set();
  }
  std::vector<py::ssize_t> shape(array.shape(), array.shape() + array.ndim());
  Int32Array out(shape);
  const std::int64_t* in = wide.data();
  std::int32_t* to = out.mutable_data();
  for (py::ssize_t i = 0; i < wide.size(); ++i) {
    if (in[i] < std::numeric_limits<std::int32_t>::min() ||
        in[i] > std::numeric_limits<std::int32_t>::max()) {
      throw py::value_error(std::string(name) + ": value " + std::to_string(in[i]) +
                            " does not fit int32");
    }
    to[i] = static_cast<std::int32_t>(in[i]);
  }
  return out;
}

std::vector<SurfacePoint> surface_points(const py::handle& face, const py::handle& uv) {
  const Int32Array faces = int_rows(face, "face", 0);
  const Float64Array params = float_rows(uv, "uv", 2);
  if (faces.shape(0) != params.shape(0)) {
    throw py::value_error("face and uv: expected the same number of points, got " +
                          std::to_string(faces.shape(0)) + " and " +
                          std::to_string(params.shape(0)));
  }
  std::vector<SurfacePoint> points(static_cast<std::size_t>(faces.shape(0)));
  const auto f = faces.unchecked<1>();
  const auto p = params.unchecked<2>();
  for (py::ssize_t i = 0; i < faces.shape(0); ++i) {
    points[static_cast<std::size_t>(i)] = {f(i), p(i, 0), p(i, 1)};
  }
  return points;
}

Float64Array new_rows(py::ssize_t n, int columns) {
  if (columns == 0) {
    return Float64Array(std::vector<py::ssize_t>{n});
  }
  return Float64Array(std::vector<py::ssize_t>{n, columns});
}

Int32Array new_ints(py::ssize_t n, int columns) {
  if (columns == 0) {
    return Int32Array(std::vector<py::ssize_t>{n});
  }
  return Int32Array(std::vector<py::ssize_t>{n, columns});
}

Float64Array rows_of(const Eigen::Matrix3Xd& columns) {
  Float64Array out = new_rows(columns.cols(), 3);
  Eigen::Map<Eigen::Matrix3Xd>(out.mutable_data(), 3, columns.cols()) = columns;
  return out;
}

Float64Array rows_of(std::span<const Eigen::Vector3d> vectors) {
  Float64Array out = new_rows(static_cast<py::ssize_t>(vectors.size()), 3);
  std::copy(vectors.begin(), vectors.end(), reinterpret_cast<Eigen::Vector3d*>(out.mutable_data()));
  return out;
}

Int32Array triangles_of(std::span<const Eigen::Vector3i> triangles) {
  Int32Array out = new_ints(static_cast<py::ssize_t>(triangles.size()), 3);
  std::copy(triangles.begin(), triangles.end(),
            reinterpret_cast<Eigen::Vector3i*>(out.mutable_data()));
  return out;
}

py::dict points_dict(std::span<const SurfacePoint> points) {
  const auto n = static_cast<py::ssize_t>(points.size());
  Int32Array face = new_ints(n);
  Float64Array uv = new_rows(n, 2);
  auto f = face.mutable_unchecked<1>();
  auto p = uv.mutable_unchecked<2>();
  for (py::ssize_t i = 0; i < n; ++i) {
    const SurfacePoint& s = points[static_cast<std::size_t>(i)];
    f(i) = s.face;
    p(i, 0) = s.u;
    p(i, 1) = s.v;
  }
  py::dict out;
  out["face"] = face;
  out["uv"] = uv;
  return out;
}

}  // namespace elastic::python
