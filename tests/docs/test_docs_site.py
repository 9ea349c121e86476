"""The site's set-up, without building it (issue 31 item 2; the build itself:
tests/docs/test_docs_build.py):

* the stylesheet docs/conf.py declares exists and makes long commands wrap and wide tables fit
  (no horizontal scrolling), and its font stacks carry CJK-capable families before the generic
  one (the book's title, 仿生机械学, rendered as boxes without them);
* a GitHub Pages workflow builds the site with the README's command and publishes it;
* README's notebook list names every notebook of notebooks/.
"""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
CJK = ("Noto Sans CJK SC", "Source Han Sans SC", "Microsoft YaHei")


def conf_value(name: str):
    ns: dict = {}
    text = (DOCS / "conf.py").read_text(encoding="utf-8")
    m = re.search(rf"^{name}\s*=\s*(.+)$", text, re.M)
    assert m, f"docs/conf.py sets no {name}"
    exec(f"{name} = {m.group(1)}", ns)  # a literal list
    return ns[name]


def test_the_stylesheet_wraps_code_fits_tables_and_has_cjk_fonts():
    static = conf_value("html_static_path")
    css_files = conf_value("html_css_files")
    assert css_files
    css = "".join((DOCS / static[0] / f).read_text(encoding="utf-8") for f in css_files)
    pre = re.search(r"div\.highlight pre[^{]*\{([^}]*)\}", css)
    assert pre and "pre-wrap" in pre.group(1), "long commands must wrap"
    cells = re.search(r"table td, [^{]*\{([^}]*)\}", css)
    assert cells and "white-space: normal" in cells.group(1) and "overflow-wrap" in cells.group(1)
    stack = re.search(r"--anthroarm-cjk:([^;]*);", css).group(1)
    for family in CJK:
        assert f'"{family}"' in stack, family
    # the heading (the book's title) and body stacks end with the CJK families, then the generic
    for var in ("--pst-font-family-base", "--pst-font-family-heading"):
        decl = re.search(rf"{var}:([^;]*);", css).group(1)
        assert "var(--anthroarm-cjk)" in decl or "--pst-font-family-base" in decl, var
    assert re.search(r"h1[^{]*\{[^}]*var\(--anthroarm-cjk\), sans-serif", css)


def test_a_workflow_publishes_the_site_with_the_readmes_command():
    """Read as text (no YAML parser among the test dependencies)."""
    wf = (ROOT / ".github" / "workflows" / "docs.yml").read_text(encoding="utf-8")
    assert re.search(r"^on:\s*\n\s+push:\s*\n\s+branches: \[main\]", wf, re.M)
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    command = "python -m sphinx -W --keep-going -b html docs docs/_build/html"
    assert command in readme and command in wf, "the workflow builds as README says"
    assert 'pip install -e ".[docs]"' in wf, "with the extra README names"
    assert "uses: actions/upload-pages-artifact@" in wf
    assert "uses: actions/deploy-pages@" in wf
    assert re.search(r"permissions:\s*\n\s+pages: write\s*\n\s+id-token: write", wf)


def test_readme_lists_every_notebook():
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    listed = set(re.findall(r"\(notebooks/(\w+)\.ipynb\)", readme))
    have = {p.stem for p in (ROOT / "notebooks").glob("*.ipynb")}
    assert have <= listed, f"README's notebook list misses {sorted(have - listed)}"
