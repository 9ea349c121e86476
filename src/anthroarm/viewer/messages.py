"""The commands the viewer sends, as the dicts meshcat's protocol packs (and the in-memory
:class:`~anthroarm.viewer._store.SceneStore` applies): ``set_transform``, ``set_object``,
``set_property``, ``delete``, ``set_animation``, plus anthroarm's ``anthroarm_color`` and
``anthroarm_ui`` (see :mod:`anthroarm.viewer._store`).  Paths are meshcat paths
(``/meshcat/...``)."""

from __future__ import annotations

import re

import meshcat.geometry as mg
import numpy as np
from meshcat.commands import SetObject

from .colors import rgb_hex

#: Where every Viewer draws: ``ROOT/<robot name>`` (``viewer.root``).
ROOT = "/meshcat/anthroarm"


def safe_name(name: str) -> str:
    """``name`` as one meshcat path element (anything but letters, digits, ``_.-`` -> ``_``)."""
    return re.sub(r"[^A-Za-z0-9_.\-]", "_", str(name)) or "_"


def set_transform(path: str, T: np.ndarray) -> dict:
    """Place ``path`` at the 4×4 pose ``T`` in its parent's frame."""
    return {
        "type": "set_transform",
        "path": path,
        "matrix": np.asarray(T, float).T.ravel().tolist(),
    }


def set_object(
    path: str, geometry, rgb=(0.7, 0.7, 0.7), opacity: float = 1.0, material=None
) -> dict:
    """Draw ``geometry`` at ``path``: a Phong material of ``rgb`` and ``opacity`` unless
    ``material`` is given (a meshcat ``Object``, e.g. a point cloud, carries its own)."""
    if material is None:
        kw = {"color": rgb_hex(rgb)}
        if opacity < 1.0:
            kw.update(opacity=float(opacity), transparent=True)
        material = mg.MeshPhongMaterial(**kw)
    if isinstance(geometry, mg.Object):
        cmd = SetObject(geometry)
    else:
        cmd = SetObject(geometry, material)
    d = cmd.lower()
    d["path"] = path
    return d


def set_property(path: str, key: str, value) -> dict:
    """Set one property (``visible``, ``position``, ``top_color`` ...) of the node at ``path``."""
    return {"type": "set_property", "path": path, "property": key, "value": value}


def delete(path: str) -> dict:
    """Remove ``path`` and everything under it."""
    return {"type": "delete", "path": path}


def set_color(path: str, rgb) -> dict:
    """Recolour every mesh under ``path`` (``anthroarm_color``), without resending geometry."""
    return {"type": "anthroarm_color", "path": path, "color": list(rgb)}


def ui(path: str, spec: dict) -> dict:
    """An HTML overlay on the page (``anthroarm_ui``: a legend, a note, the teach sliders)."""
    return {"type": "anthroarm_ui", "path": path, "spec": spec}


def stop_animation() -> dict:
    """Stop and forget the animation (an empty ``set_animation``)."""
    return {
        "type": "set_animation",
        "path": "",
        "animations": [],
        "options": {"play": False, "repetitions": 1},
    }
