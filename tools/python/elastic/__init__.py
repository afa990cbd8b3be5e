"""ElasticPaint for Python: least-distortion maps between surface regions.

The C++ library (libelastic) with NumPy arrays at its edge. Conventions (docs/python.md):

- points and vectors: ``(N, 3) float64`` arrays;
- a surface point: a ptex face and parameters in it, passed as two arrays,
  ``face`` ``(N,) int32`` and ``uv`` ``(N, 2) float64``;
- triangles: ``(T, 3) int32``; polygon faces ``(F, k) int32``.

Errors are :class:`elastic.Error` subclasses whose messages name the input:
:class:`InvalidInputError` (also a ``ValueError``), :class:`IoError` (also an
``OSError``) and :class:`NumericalError` (also an ``ArithmeticError``). Wrong array
shapes or dtypes raise ``ValueError`` naming the argument.

Example::

    import elastic
    cap = elastic.Surface("hemisphere.off")
    plane = elastic.Surface("grid.off")
    m = elastic.map_regions(plane.region("disk:0.5,0.5,0,0.45"), cap.region("boundary"),
                            particles=2000)
    print(m.ok, m.metrics()["symmetric_dirichlet"])

A decal placed by a point, an angle and a size (a free boundary, docs/transfer.md)::

    d = elastic.place_decal(plane.region("disk:0.5,0.5,0,0.3"), cap, (0.28, 0.28, 0.92),
                            angle=25, scale=1.5, particles=2000)
    print(d.ok, d.decal["target_area"])

Batches of jobs on a Dask cluster: ``python3 -m elastic.batch JOBS...`` (elastic.batch).
"""

from ._elastic import (  # noqa: F401  (re-exported)
    Error,
    InvalidInputError,
    IoError,
    Map,
    Mesh,
    NumericalError,
    Region,
    Surface,
    image_source,
    load_mesh,
    map_regions,
    place_decal,
    save_mesh,
)

__all__ = [
    "Error",
    "InvalidInputError",
    "IoError",
    "Map",
    "Mesh",
    "NumericalError",
    "Region",
    "Surface",
    "image_source",
    "load_mesh",
    "map_regions",
    "save_mesh",
]
