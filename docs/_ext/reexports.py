"""Sphinx extension: resolve cross-references the way Python resolves the name.

The API reference documents every object once: where users import it when a package
re-exports it (``anthroarm.load``, defined as ``anthroarm.robot.load``; build_pages.PUBLIC),
else in the module that defines it (``ignore-module-all``).
When Sphinx finds no target for a reference, this looks the name up as Python would — relative
to the module and class the reference is written in, then absolute — and, if the object exists
and is documented under its defining module, links there.  A name that Python cannot find stays
a broken reference (an error under ``-W``).
"""

from __future__ import annotations

import importlib
import inspect

from build_pages import PUBLIC


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


def _public(real: str) -> str | None:
    """``real`` (a defining path) where users import it (build_pages.PUBLIC): the object
    itself, or a member of a class documented at its public path."""
    parts = real.split(".")
    for i in range(len(parts), 1, -1):
        head = ".".join(parts[:i])
        if head in PUBLIC:
            return ".".join([PUBLIC[head], *parts[i:]])
    return None


def _defined_path(name: str) -> str:
    """A documented name as the path where it is defined (the inverse of :func:`_public`)."""
    back = {v: k for k, v in PUBLIC.items()}
    parts = name.split(".")
    for i in range(len(parts), 1, -1):
        head = ".".join(parts[:i])
        if head in back:
            return ".".join([back[head], *parts[i:]])
    return name


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
    if mod and "." not in target:  # a docstring moved to its package's page (build_pages):
        # its short names are relative to the module that defines it
        homes = sorted(
            {c.rpartition(".")[0] for c, p in PUBLIC.items() if p.rpartition(".")[0] == mod}
        )
        candidates += [f"{h}.{target}" for h in homes]
    domain = env.get_domain("py")
    for cand in candidates:  # a member of a class documented at its public path, by name
        moved = _public(cand)
        if moved:
            node2 = node.deepcopy()
            node2["reftarget"] = moved
            node2["refspecific"] = False
            res = domain.resolve_xref(
                env, node["refdoc"], app.builder, "obj", moved, node2, contnode
            )
            if res is not None:
                return res
    for cand in candidates:
        obj = _lookup(cand)
        if obj is None:
            continue
        real = _canonical(obj, cand)
        if not real:
            continue
        for name in (real, _public(real)):
            if not name or name == cand and cand == target:
                continue
            node2 = node.deepcopy()
            node2["reftarget"] = name
            node2["refspecific"] = False
            res = domain.resolve_xref(
                env, node["refdoc"], app.builder, "obj", name, node2, contnode
            )
            if res is not None:
                return res
    # a method or attribute named without its class (:meth:`angles` in anthroarm.chain): the one
    # documented object of that name in the same module
    if mod and "." not in target:
        hits = [
            name
            for name, _ in domain.find_obj(env, mod, None, target, None, 1)
            if _defined_path(name).startswith(mod + ".")
        ]
        if len(hits) == 1:
            return domain.resolve_xref(
                env, node["refdoc"], app.builder, "obj", hits[0], node.deepcopy(), contnode
            )
    return None


def setup(app):
    app.connect("missing-reference", missing_reference)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
