"""The model catalog: the book's arms as parameter tables (-> URDF) and example-robot-data arms.

>>> import anthroarm as aa
>>> aa.models.names()            # doctest: +ELLIPSIS
['human_arm7', 'planar2r', 'prosthetic_arm', ...]
>>> spec = aa.models.spec("prosthetic_arm", L2=0.240)   # the caption's forearm length
>>> urdf_text = aa.models.urdf_text("human_arm7", height=1.62, mass=55, sex="female")

The generated URDFs of the default parameters are committed in ``urdf/`` (a test proves they
equal the generator's output); :func:`write_urdfs` regenerates them.
"""

from __future__ import annotations

import inspect
from pathlib import Path

from .. import cache
from .._io import atomic_write_text
from ..errors import ParameterError, UnknownModelError
from .book import planar2r, prosthetic_arm, rrprr5, sixr_arm, unimate5
from .care_robot import care_robot
from .erd import ERD_ARMS, ErdArm, erd_names, erd_urdf_path
from .human import human_arm7, segment_parameters
from .human_upper_limb import human_upper_limb
from .prosthetic_hand import prosthetic_hand
from .spec import REPO_URDF_DIR, ChainSpec, DHRow, JointSpec, LinkSpec, dh_matrix, from_dh, to_urdf
from .templates import TEMPLATES

BOOK_MODELS = {
    "prosthetic_arm": prosthetic_arm,
    "human_arm7": human_arm7,
    "sixr_arm": sixr_arm,
    "unimate5": unimate5,
    "rrprr5": rrprr5,
    "planar2r": planar2r,
    "human_upper_limb": human_upper_limb,
    "care_robot": care_robot,
    # Fig. 2-8/2-9 linkages; plain URDF with fitted mimic joints
    "prosthetic_hand": prosthetic_hand,
    # Table 2.3: cartesian_robot, cylindrical_robot, spherical_robot, articulated_robot
    **TEMPLATES,
}

#: the catalog model of a person's arm, built from body height (m), mass (kg) and sex: what the
#: analyses and applications that start from a person load unless told otherwise
PERSON_ARM = "human_arm7"
#: the same arm with a five-digit hand (the fingertips are frames of the model)
PERSON_ARM_WITH_HAND = "human_upper_limb"

#: units of the builder parameters that are not lengths in m (the catalog's convention; mass is
#: kg everywhere): shown by ``anthroarm urdf MODEL --help``
PARAM_UNITS: dict[str, dict[str, str]] = {
    "cylindrical_robot": {"base": "rad"},
    "spherical_robot": {"base": "rad", "elevation": "rad"},
    "articulated_robot": {"base": "rad", "shoulder": "rad", "elbow": "rad"},
    "prosthetic_hand": {"scale": "1"},
}


def param_unit(model: str, param: str) -> str:
    """Unit of a builder parameter of a book model: :data:`PARAM_UNITS`, else kg for ``mass``
    and m for the rest."""
    return PARAM_UNITS.get(model, {}).get(param, "kg" if param == "mass" else "m")


def names() -> list[str]:
    """Every catalog name: the book's models, then the example-robot-data arms."""
    return sorted(BOOK_MODELS) + sorted(ERD_ARMS)


def book_names() -> list[str]:
    return sorted(BOOK_MODELS)


def _unknown(name) -> UnknownModelError:
    return UnknownModelError(
        f"unknown model {name!r}; the catalog has: {', '.join(names())}; "
        f"example-robot-data has: {', '.join(n for n in erd_names() if n not in ERD_ARMS)}; "
        "or give a URDF path"
    )


def spec(name: str, **params) -> ChainSpec:
    """Parameter table of a book model; ``params`` are the builder's keyword arguments."""
    if name not in BOOK_MODELS:
        raise _unknown(name)
    try:
        return BOOK_MODELS[name](**params)
    except TypeError as exc:
        sig = inspect.signature(BOOK_MODELS[name])
        raise ParameterError(
            f"{name}: bad parameters {params}; accepted: {list(sig.parameters)} ({exc})"
        ) from None


def urdf_text(name: str, **params) -> str:
    """URDF text of a book model with the given parameters."""
    return to_urdf(spec(name, **params))


def urdf_path(name: str) -> Path:
    """Path of the URDF of a catalog model (default parameters): the example-robot-data file,
    or for a book model the committed ``urdf/NAME.urdf`` of a source checkout; in an installed
    package, the generator's text (the same file, tested) written into the cache's ``urdf``
    folder and rewritten whenever it differs.  Write one anywhere with :func:`urdf_text` /
    ``anthroarm urdf``."""
    if name in ERD_ARMS:
        return ERD_ARMS[name].urdf_path()
    if name in erd_names():
        return erd_urdf_path(name)
    if name not in BOOK_MODELS:
        raise _unknown(name)
    p = REPO_URDF_DIR / f"{name}.urdf"
    if p.is_file():
        return p
    folder = cache.folder("urdf")
    if folder is None:
        raise FileNotFoundError(
            f"{p} does not exist (not a source checkout) and {cache.status()}; "
            f"use anthroarm.models.urdf_text({name!r})"
        )
    p, text = folder / f"{name}.urdf", urdf_text(name)
    if not p.is_file() or p.read_text(encoding="utf-8") != text:
        atomic_write_text(p, text)
    return p


def write_urdfs(out_dir=None) -> list[Path]:
    """(Re)generate the URDFs of all book models with default parameters into ``out_dir``."""
    out = Path(out_dir) if out_dir is not None else REPO_URDF_DIR
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    for n in sorted(BOOK_MODELS):
        p = out / f"{n}.urdf"
        atomic_write_text(p, urdf_text(n))
        paths.append(p)
    return paths


__all__ = [
    "BOOK_MODELS",
    "PERSON_ARM",
    "PERSON_ARM_WITH_HAND",
    "ERD_ARMS",
    "ErdArm",
    "ChainSpec",
    "DHRow",
    "JointSpec",
    "LinkSpec",
    "dh_matrix",
    "from_dh",
    "to_urdf",
    "names",
    "book_names",
    "spec",
    "urdf_text",
    "urdf_path",
    "write_urdfs",
    "erd_names",
    "erd_urdf_path",
    "human_arm7",
    "prosthetic_arm",
    "sixr_arm",
    "unimate5",
    "rrprr5",
    "planar2r",
    "segment_parameters",
    "care_robot",
]
