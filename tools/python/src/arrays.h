#pragma once
// NumPy arrays at the binding's edge: shape and dtype checks that name the argument, views of
// C-contiguous float64 / int32 arrays as the library's types without a copy, and new arrays for
// results. Conventions (docs/python.md): points and vectors are N x 3 float64; surface points are
// a pair (face: N int32, uv: N x 2 float64); triangles are T x 3 int32.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <Eigen/Core>
#include <span>
#include <string>
#include <vector>

#include "elastic/surface/surface_point.h"

namespace elastic::python {

namespace py = pybind11;

using Float64Array = py::array_t<double, py::array::c_style>;
using Int32Array = py::array_t<std::int32_t, py::array::c_style>;

/// "(3, 4)" for a message.
std::string shape_text(const py::array& array);

/// `object` as a C-contiguous float64 array of shape (N, columns) (columns 0: shape (N,)). Floating
/// and integer inputs in another dtype or layout are converted (a copy); anything else, or another
/// shape, raises ValueError naming `name`.
Float64Array float_rows(const py::handle& object, const char* name, int columns);
/// The same for int32 arrays (integer dtypes only, values range-checked by the caller).
Int32Array int_rows(const py::handle& object, const char* name, int columns);

/// A (N, 3) float64 array viewed as N Eigen vectors (no copy: Vector3d is three packed doubles).
inline std::span<const Eigen::Vector3d> as_vectors(const Float64Array& rows) {
  return {reinterpret_cast<const Eigen::Vector3d*>(rows.data()),
          static_cast<std::size_t>(rows.shape(0))};
}

/// Surface points from (face, uv) arrays of matching lengths.
std::vector<SurfacePoint> surface_points(const py::handle& face, const py::handle& uv);

/// New arrays for results.
Float64Array new_rows(py::ssize_t n, int columns);
Int32Array new_ints(py::ssize_t n, int columns = 0);

/// (N, 3) float64 copy of a 3 x N Eigen matrix, and of N vectors.
Float64Array rows_of(const Eigen::Matrix3Xd& columns);
Float64Array rows_of(std::span<const Eigen::Vector3d> vectors);
/// (T, 3) int32 copy of triangles.
Int32Array triangles_of(std::span<const Eigen::Vector3i> triangles);
/// {"face": N int32, "uv": N x 2 float64} for surface points (face -1 where unset).
py::dict points_dict(std::span<const SurfacePoint> points);

}  // namespace elastic::python
