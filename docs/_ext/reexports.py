"""Sphinx extension: resolve cross-references the way Python resolves the name.

The API reference documents every object once, in the module that defines it
(``ignore-module-all``); packages re-export names (``anthroarm.load`` is
``anthroarm.robot.load``, ``qp.IKConfiguration`` lives in ``anthroarm.ik.qp.configuration``).
When Sphinx finds no target for a reference, this looks the name up as Python would — relative
to the module and class the reference is written in, then absolute — and, if the object exists
and is documented under its defining module, links there.  A name that Python cannot find stays
a broken reference (an error under ``-W``).
"""

from __future__ import annotations

import importlib
import inspect


def _lookup(path: str):
    parts = path.split(".")
    for i in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:i]))
        except Exception:
            continue
        try:
            for p in parts[i:]:
                obj = getattr(obj, p)
        except AttributeError:
            return None
        return obj
    return None


def _canonical(obj, fallback: str) -> str | None:
    if inspect.ismodule(obj):
        return obj.__name__
    fn = getattr(obj, "__func__", obj)
    mod, qual = getattr(fn, "__module__", None), getattr(fn, "__qualname__", None)
    if mod and qual and "<" not in qual:
        return f"{mod}.{qual}"
    if isinstance(obj, property) and fallback:
        owner, _, name = fallback.rpartition(".")
        cls = _lookup(owner)
        if inspect.isclass(cls):
            return f"{cls.__module__}.{cls.__qualname__}.{name}"
    return None


def missing_reference(app, env, node, contnode):
    if node.get("refdomain") != "py":
        return None
    target = node["reftarget"].lstrip(".~")
    mod, cls = node.get("py:module"), node.get("py:class")
    candidates = []
    if mod and cls:
        candidates.append(f"{mod}.{cls}.{target}")
    if mod:
        parts = mod.split(".")
        candidates += [".".join(parts[:i] + [target]) for i in range(len(parts), 0, -1)]
    candidates.append(target)
    domain = env.get_domain("py")
    for cand in candidates:
        obj = _lookup(cand)
        if obj is None:
            continue
        real = _canonical(obj, cand)
        if not real or real == cand and cand == target:
            continue
        node2 = node.deepcopy()
        node2["reftarget"] = real
        node2["refspecific"] = False
        res = domain.resolve_xref(env, node["refdoc"], app.builder, "obj", real, node2, contnode)
        if res is not None:
            return res
    # a method or attribute named without its class (:meth:`angles` in anthroarm.chain): the one
    # documented object of that name in the same module
    if mod and "." not in target:
        hits = [
            name
            for name, _ in domain.find_obj(env, mod, None, target, None, 1)
            if name.startswith(mod + ".")
        ]
        if len(hits) == 1:
            return domain.resolve_xref(
                env, node["refdoc"], app.builder, "obj", hits[0], node.deepcopy(), contnode
            )
    return None


def setup(app):
    app.connect("missing-reference", missing_reference)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
