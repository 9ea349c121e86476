"""Pages of the docs site generated from the repository at build time (called by docs/conf.py).

Nothing here is committed: each build regenerates the pages from the files they describe, so
the site cannot drift from the notebooks, the committed benchmark results or the docstrings.
"""

from __future__ import annotations

import importlib
import inspect
import json
import pkgutil
import re
import shutil
from collections import defaultdict
from pathlib import Path

#: "Eq. (6-12)", "Eqs. (7-17)–(7-20)", "Eq. (5-87′)", "Eqs. (6-117) and (6-118)"
EQ_RUN = re.compile(r"Eqs?\.\s*((?:\(\d+-\d+[′']?\)(?:\s*(?:–|—|-|…|\.\.\.|,|and|or|to)\s*)?)+)")
EQ_ID = re.compile(r"\((\d+)-(\d+)([′']?)\)")

CHAPTERS = {
    2: "Ch. 2 — structure of the arm and hand, grasp error",
    3: "Ch. 3 — motion curves and linkage synthesis",
    4: "Ch. 4 — optimisation",
    5: "Ch. 5 — mathematics: rotations, dual numbers, screws",
    6: "Ch. 6 — kinematics of arms, hands and mechanisms",
    7: "Ch. 7 — inverse kinematics and control of the arm",
    8: "Ch. 8 — dynamics",
    9: "Ch. 9 — control, EMG, prostheses",
}


def _is_function(obj) -> bool:
    """A function, or an object that wraps one and says so (``__wrapped__``: anthroarm's
    compiled kernels, :class:`anthroarm.jit.Kernel`)."""
    try:
        return inspect.isfunction(inspect.unwrap(obj))
    except ValueError:  # a cycle of __wrapped__
        return False


def write_if_changed(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    if not path.is_file() or path.read_text(encoding="utf-8") != text:
        path.write_text(text, encoding="utf-8")


# ------------------------------------------------------------------------------- notebooks
def copy_notebooks(src: Path, dst: Path) -> list[Path]:
    """Copy ``notebooks/*.ipynb`` into the docs tree (myst-nb executes the copies).

    Markdown links into the repository's ``docs/`` folder (``../docs/errata.md``, which work on a
    code host) are rewritten to the site's page (``../errata.md``) so that Sphinx resolves them."""
    dst.mkdir(parents=True, exist_ok=True)
    keep = set()
    for nb in sorted(src.glob("*.ipynb")):
        data = json.loads(nb.read_text(encoding="utf-8"))
        for cell in data.get("cells", []):
            if cell.get("cell_type") == "markdown":
                src_text = (
                    "".join(cell["source"]) if isinstance(cell["source"], list) else cell["source"]
                )
                cell["source"] = src_text.replace("](../docs/", "](../")
        write_if_changed(dst / nb.name, json.dumps(data, indent=1, ensure_ascii=False) + "\n")
        keep.add(nb.name)
    for stale in dst.glob("*.ipynb"):
        if stale.name not in keep:
            stale.unlink()
    return sorted(dst / n for n in keep)


# ------------------------------------------------------------------------------- benchmarks
TABLE_DELIMITER = re.compile(r"^\|(?:\s*:?-+:?\s*\|)+\s*$")


def escape_cell_bars(text: str) -> str:
    """Escape each "|" written inside a table cell (``| max |x - x*| |``) as ``\\|``.

    Markdown splits such a row into more cells than the delimiter row has columns, and the table
    is then not a table at all (the benchmark tables name ``|q diff|`` and ``|x - x*|``).  A
    column separator is written `` | `` (space or another "|" on both sides, or at either end of
    the row); any other "|" of a table row is text."""
    out = []
    for line in text.split("\n"):
        row = line.rstrip()
        if (
            row.startswith("|")
            and row.endswith("|")
            and len(row) > 1
            and not TABLE_DELIMITER.match(row)
        ):
            cells = []
            for i, ch in enumerate(row):
                inner = 0 < i < len(row) - 1
                prev, nxt = row[i - 1] if i else " ", row[i + 1] if i + 1 < len(row) else " "
                if ch == "|" and inner and prev != "\\" and (prev not in " |" or nxt not in " |"):
                    cells.append("\\|")
                else:
                    cells.append(ch)
            line = "".join(cells)
        out.append(line)
    return "\n".join(out)


def benchmark_pages(results: Path, dst: Path) -> list[str]:
    """One page per committed ``benchmarks/results/NAME.md``, with the plots ``NAME*.png``."""
    if dst.exists():
        shutil.rmtree(dst)
    dst.mkdir(parents=True)
    names = []
    for md in sorted(results.glob("*.md")):
        name = md.stem
        text = md.read_text(encoding="utf-8").rstrip() + "\n"
        # the tables' own relative mentions of results/ files are plain text on the site
        text = text.replace("](results/", "](")
        text = escape_cell_bars(text)
        plots = sorted(p for p in results.glob(f"{name}*.png"))
        if plots:
            text += "\n## Plots\n\n"
            for p in plots:
                shutil.copy2(p, dst / p.name)
                text += f"```{{image}} {p.name}\n:alt: {p.stem}\n:width: 100%\n```\n\n"
        run_json = results / f"{name}.json"
        text += (
            f"\n---\n\nSource: `benchmarks/results/{name}.md`"
            + (f" and `{run_json.name}` (every number of the run)" if run_json.is_file() else "")
            + f"; re-run with `anthroarm bench {name}` in a source checkout.\n"
        )
        write_if_changed(dst / f"{name}.md", f"(bench-{name})=\n" + text)
        names.append(name)
    return names


# ------------------------------------------------------------------------------- equations
def _public_modules(package: str = "anthroarm") -> list[str]:
    pkg = importlib.import_module(package)
    mods = [package]
    for info in pkgutil.walk_packages(pkg.__path__, prefix=package + "."):
        if any(part.startswith("_") for part in info.name.split(".")):
            continue
        mods.append(info.name)
    return mods


def _eq_ids(doc: str) -> list[tuple[int, int, str]]:
    ids = []
    for run in EQ_RUN.finditer(doc or ""):
        for m in EQ_ID.finditer(run.group(1)):
            ids.append((int(m.group(1)), int(m.group(2)), m.group(3)))
    return ids


def collect_equations(
    package: str = "anthroarm",
) -> dict[tuple[int, int, str], list[tuple[str, str]]]:
    """{(chapter, number, prime): [(role, target)]}: where each equation is named in a docstring.

    role is ``mod``, ``class``, ``func`` or ``meth``; the target is documented on the API pages
    (public modules, public names defined in the module they are documented in)."""
    where: dict = defaultdict(list)

    def add(doc, role, target):
        for eq in _eq_ids(doc):
            if (role, target) not in where[eq]:
                where[eq].append((role, target))

    for modname in _public_modules(package):
        mod = importlib.import_module(modname)
        add(mod.__doc__, "mod", modname)
        for name, obj in vars(mod).items():
            if name.startswith("_") or getattr(obj, "__module__", None) != modname:
                continue
            if inspect.isclass(obj):
                add(obj.__doc__, "class", f"{modname}.{name}")
                for mname, meth in vars(obj).items():
                    if mname.startswith("_"):
                        continue
                    fn = meth.__func__ if isinstance(meth, (staticmethod, classmethod)) else meth
                    if isinstance(fn, property):
                        add(fn.__doc__, "attr", f"{modname}.{name}.{mname}")
                    elif _is_function(fn):
                        add(fn.__doc__, "meth", f"{modname}.{name}.{mname}")
            elif _is_function(obj):
                add(obj.__doc__, "func", f"{modname}.{name}")
    return dict(where)


def equation_table(out: Path, package: str = "anthroarm") -> int:
    """Write the book map's equation table (a MyST page fragment); returns the number of equations."""
    where = collect_equations(package)
    by_ch: dict = defaultdict(list)
    for eq in sorted(where):
        by_ch[eq[0]].append(eq)
    lines = [
        f"Every equation of the book named in a docstring — {len(where)} equations, found by "
        "searching the docstrings for `Eq. (…)` when this site was built — with the functions, "
        "classes and modules that implement or use it.",
        "",
    ]
    for ch in sorted(by_ch):
        lines += [
            f"### {CHAPTERS.get(ch, f'Ch. {ch}')}",
            "",
            "| equation | implemented in |",
            "|---|---|",
        ]
        for eq in by_ch[ch]:
            refs = ", ".join(
                f"{{py:{role}}}`~{target}`" if role != "mod" else f"{{py:mod}}`{target}`"
                for role, target in where[eq]
            )
            lines.append(f"| ({eq[0]}-{eq[1]}{eq[2]}) | {refs} |")
        lines.append("")
    write_if_changed(out, "\n".join(lines) + "\n")
    return len(where)


# ------------------------------------------------------------------------------- API pages
def _exported(mod) -> list[str]:
    """A package's re-exported names: its ``__all__``, else its public attributes that are
    functions or classes defined in one of its submodules (``anthroarm.ik.analytic``)."""
    if hasattr(mod, "__all__"):
        return list(mod.__all__)
    return [
        n
        for n, o in vars(mod).items()
        if not n.startswith("_")
        and (_is_function(o) or inspect.isclass(o))
        and getattr(o, "__module__", "").startswith(mod.__name__ + ".")
    ]


def public_paths(package: str = "anthroarm") -> dict[str, str]:
    """Where users import each re-exported function and class from: defining path -> public
    path (``anthroarm.robot.load`` -> ``anthroarm.load``).  A name a package re-exports
    (:func:`_exported`) from a deeper module is documented at the package (the shortest such
    path).  A public path that is also a module's name (``anthroarm.ik.solve``, the function and
    its subpackage) is taken only when that module has nothing else of its own to document (its
    page then gets no index entry: :data:`SHADOWED`); otherwise the name stays where it is
    defined."""
    mods = _public_modules(package)
    modset = set(mods)
    out: dict[str, str] = {}
    for m in mods:
        mod = importlib.import_module(m)
        if not hasattr(mod, "__path__"):
            continue
        for name in _exported(mod):
            obj = getattr(mod, name, None)
            if not (_is_function(obj) or inspect.isclass(obj)):
                continue
            canon = f"{obj.__module__}.{obj.__qualname__}"
            public = f"{m}.{name}"
            if canon == public or not canon.startswith(package + "."):
                continue
            if canon not in out or len(public) < len(out[canon]):
                out[canon] = public
    SHADOWED.clear()
    for canon, public in list(out.items()):
        if public not in modset:
            continue
        own = _own_members(public)
        if all(f"{public}.{n}" in out for n in own):
            SHADOWED.add(public)
        else:
            del out[canon]
    return out


def _own_members(module: str) -> list[str]:
    mod = importlib.import_module(module)
    return [
        n
        for n, o in vars(mod).items()
        if not n.startswith("_")
        and (_is_function(o) or inspect.isclass(o))
        and getattr(o, "__module__", None) == module
    ]


#: modules whose name is also a public function's (their page has no index entry)
SHADOWED: set[str] = set()


def api_pages(dst: Path, package: str = "anthroarm") -> list[str]:
    """One reST page per public module (``automodule``), its submodules in a toctree.

    Written here rather than by autosummary's recursion: several packages re-export a function
    under the name of its module (``anthroarm.mechanisms.fourbar`` is both), which autosummary
    resolves to the function."""
    mods = _public_modules(package)
    public = public_paths(package)
    if dst.exists():
        shutil.rmtree(dst)
    dst.mkdir(parents=True)
    for m in mods:
        children = [c for c in mods if c.rpartition(".")[0] == m]
        text = f"{m}\n{'=' * len(m)}\n\n.. automodule:: {m}\n"
        if m in SHADOWED:  # the name is the function's (documented on the package's page)
            text += "   :no-index:\n"
        here = sorted((p, c) for c, p in public.items() if p.rpartition(".")[0] == m)
        if here:  # the names users import from this package, documented at that path
            text += "\n.. rubric:: Imported from here\n\n"
            for p, c in here:
                kind = "class" if inspect.isclass(_object(c)) else "function"
                text += f".. auto{kind}:: {p}\n\n"
        if children:
            text += "\n.. rubric:: Submodules\n\n.. toctree::\n   :maxdepth: 1\n\n"
            text += "".join(f"   {c}\n" for c in children)
        (dst / f"{m}.rst").write_text(text, encoding="utf-8")
    return mods


_LITERAL = re.compile(r"(``.*?``|`[^`]*`_?|:math:`[^`]*`)")


def escape_bars(app, what, name, obj, options, lines):
    """autodoc-process-docstring: a ``|x|`` (a norm, an absolute value) in plain docstring text
    is a docutils substitution reference; escape the bars outside literals and tables."""
    for i, line in enumerate(lines):
        s = line.strip()
        if "|" not in line or s.startswith("+") or (s.startswith("|") and s.endswith("|")):
            continue  # a grid table's row
        parts = _LITERAL.split(line)
        lines[i] = "".join(p if j % 2 else p.replace("|", "\\|") for j, p in enumerate(parts))
    # Markdown habit: a bullet list right under a line of text; reST needs a blank line first
    i = 1
    while i < len(lines):
        cur, prev = lines[i].lstrip(), lines[i - 1]
        if (
            cur.startswith(("* ", "- "))
            and prev.strip()
            and not prev.lstrip().startswith(("* ", "- "))
            and len(lines[i]) - len(cur) <= len(prev) - len(prev.lstrip())
        ):
            lines.insert(i, "")
            i += 1
        i += 1


def _object(path: str):
    mod, _, rest = path.partition(".")
    obj = importlib.import_module(mod)
    parts = rest.split(".")
    for i in range(len(parts)):  # the longest importable module prefix, then attributes
        try:
            obj = importlib.import_module(".".join([mod, *parts[: i + 1]]))
        except ImportError:
            for p in parts[i:]:
                obj = getattr(obj, p)
            return obj
    return obj


def skip_moved(app, what, name, obj, skip, options):
    """autodoc-skip-member: a function or class documented where users import it
    (:func:`public_paths`) is not documented a second time in the module that defines it."""
    if what == "module" and (_is_function(obj) or inspect.isclass(obj)):
        canon = f"{getattr(obj, '__module__', '')}.{getattr(obj, '__qualname__', '')}"
        if canon in PUBLIC:
            return True
    return None


#: defining path -> public path, filled once by conf.py (:func:`public_paths`)
PUBLIC: dict[str, str] = {}


def skip_shadowing(app, what, name, obj, skip, options):
    """autodoc-skip-member: a package's function that has the name of one of its submodules
    (``anthroarm.models.spec``) would take the module's place in the index; it is skipped on
    the package page and listed in the package docstring instead."""
    if what == "module" and _is_function(obj):
        mod = importlib.import_module(obj.__module__)
        if hasattr(mod, "__path__") and (Path(mod.__file__).parent / f"{name}.py").is_file():
            return True
    return None
