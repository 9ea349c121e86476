"""The one list of modules that anthroarm may import inside a function (DESIGN.md, issue 29
item 1): optional dependencies and heavy ones.  Every other import sits at the top of its
module; ``tests/packaging/test_function_imports.py`` holds the code to this list.

A name covers the module and its submodules (``"scipy.optimize"`` covers
``scipy.optimize._minimize``; ``"scipy"`` itself is not listed: ``scipy.linalg`` is loaded by
``import anthroarm`` anyway).  numpy, the core of scipy, pinocchio, lxml, the standard library
and anthroarm's own modules are not on the list.

Import times are cumulative (``python -X importtime``) on top of what ``import anthroarm``
already loads (numpy, scipy.linalg, pinocchio, lxml), measured on the development machine;
they say why a module is here, not a bound.
"""

from __future__ import annotations

#: not installed with anthroarm's base dependencies: extras (``test``, ``bench``), the peers the
#: benchmarks compare with, the QP backends that qpsolvers loads only when chosen by name, and
#: the repository's own ``benchmarks`` package
OPTIONAL: frozenset[str] = frozenset(
    {
        "benchmarks",  # the repository's benchmark suite (not part of the wheel)
        "IPython",  # Jupyter display of the viewer (notebooks only)
        "xarray",  # dask results as labelled arrays, when installed
        "quadprog",  # QP backends, each loaded when chosen by name
        "daqp",
        "proxsuite",
        "osqp",
        "ik_geo",  # peers (oracles for counts and speed in benchmarks and tests)
        "pink",
        "ikpy",
        "roboticstoolbox",
        "pytracik",
        "mink",
        "neurokit2",
        "opensim",
        # a base dependency, but one whose failure is tolerated where it is imported (package
        # folders for package:// URIs; example-robot-data names in the catalog), and not loaded
        # by `import anthroarm` (~250 ms alone, 2-3 ms once pinocchio is loaded)
        "example_robot_data",
    }
)

#: base dependencies that are slow to import (cumulative ms, see above) or named by DESIGN.md
#: as a capability's own dependency; imported where the capability is first used
HEAVY: frozenset[str] = frozenset(
    {
        "sympy",  # ~500-600 ms: symbolic Lagrange dynamics, code generation
        "matplotlib",  # ~700 ms (pyplot): plots at the edges
        "dask",  # ~260 ms: batch jobs on a cluster
        "distributed",  # ~380 ms
        "ezc3d",  # ~10-20 ms, named by DESIGN.md: C3D motion capture in
        "meshcat",  # ~450 ms: the browser viewer
        "tornado",  # ~120-150 ms (tornado.web): the viewer's server
        "trimesh",  # ~460 ms: meshes of example-robot-data arms
        "yourdfpy",  # ~490 ms: URDF meshes for the viewer
        "qpsolvers",  # ~170-250 ms: the QP front end of ik.qp
        "numba",  # ~150-250 ms (+ compiled kernels): anthroarm.jit
        "scipy.sparse",  # ~150 ms: the sparse matrices of the OSQP backend (ik.qp)
        "scipy.optimize",  # ~190 ms
        "scipy.integrate",  # ~220 ms
        "scipy.interpolate",  # ~270 ms
        "scipy.signal",  # ~800 ms
    }
)

#: anthroarm modules compiled by Numba when imported (:mod:`anthroarm.jit`): importing one
#: loads Numba and its cached kernels, which ``import anthroarm`` and reading a model avoid
KERNEL_MODULES: frozenset[str] = frozenset({"anthroarm.chain_kernels"})

#: everything that may be imported inside a function
ALLOWED: frozenset[str] = OPTIONAL | HEAVY | KERNEL_MODULES


def allowed(module: str) -> bool:
    """Whether ``module`` (dotted, absolute) may be imported inside a function: it or one of
    its parent packages is in :data:`ALLOWED`."""
    parts = module.split(".")
    return any(".".join(parts[:i]) in ALLOWED for i in range(1, len(parts) + 1))


__all__ = ["ALLOWED", "HEAVY", "KERNEL_MODULES", "OPTIONAL", "allowed"]
