"""Every code block of the README and the guides runs as written, and the numbers they quote
match the committed benchmark tables.

* **Python blocks.**  Every fenced ```` ```python ```` block of ``README.md``, ``docs/*.md`` and
  ``docs/guide/*.md`` is run, a page's blocks in order in ONE fresh namespace per page (as a
  reader pastes them into one session; the README's blocks, sections apart, each in its own:
  :data:`SELF_CONTAINED`), in a subprocess per page with a temporary working directory and
  ``ANTHROARM_CACHE`` unset (the default cache folder, as a user has it).  A traceback names the
  page and the Markdown line.  A block preceded by the HTML comment
  ``<!-- snippet: xfail REASON -->`` is expected to raise (a known bug in the library, named in
  REASON): it must raise, and the page goes on after it; ``<!-- snippet: skip REASON -->`` is
  not run (a block that needs a cluster).  A block that only shows output is ```` ```text ````,
  a shell session ```` ```bash ````.
* **Shell blocks.**  After the page's Python blocks, in the same folder (a command may read a
  file a block wrote), every ``anthroarm ...`` line of its ```` ```bash ```` blocks is run, except
  a live viewer (``view`` / ``teach`` without ``--html``, which serve until interrupted), the
  long jobs of :data:`SLOW_COMMANDS` and a command an earlier page already ran: those are only
  parsed by the CLI's own parser (an unknown flag fails).  Lines that install things or build
  the site do not start with ``anthroarm`` and are not run.
* **Quoted numbers.**  The numbers the pages quote from ``benchmarks/results/*.md`` that can be
  tied mechanically (:func:`quotes`: the viewer's poses/s and notebook size, the hand and grasp
  step times, the EMG chain, marker IK) are rebuilt from the committed tables and looked up in
  the pages.

Run one page: ``pytest tests/docs/test_snippets.py -k grasp``.  The whole file: ~3.5 min on the
shared 2-core machine under load, serially (most of it the pages' own work).
"""

from __future__ import annotations

import json
import os
import re
import shlex
import shutil
import subprocess
import sys
import textwrap
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
RESULTS = ROOT / "benchmarks" / "results"
PAGES = [
    ROOT / "README.md",
    *sorted((ROOT / "docs").glob("*.md")),
    *sorted((ROOT / "docs" / "guide").glob("*.md")),
]
#: pages whose blocks are each self-contained (run each in a fresh namespace): the README's
#: blocks sit sections apart, a reader copies one of them
SELF_CONTAINED = {ROOT / "README.md"}
#: a page's blocks together, on a loaded 2-core machine (the slowest page takes ~40 s)
PAGE_TIMEOUT = 300
#: a shell command of a page
COMMAND_TIMEOUT = 180

FENCE = re.compile(r"^(?P<indent> {0,3})(?P<ticks>`{3,})(?P<lang>[\w{}-]*)[^\n]*$")
MARK = re.compile(r"<!--\s*snippet:\s*(?P<kind>xfail|skip)\s+(?P<reason>.*?)\s*-->")


@dataclass
class Block:
    page: Path
    line: int  # the first code line, 1-based
    lang: str
    code: str
    mark: str = ""  # "xfail" or "skip"
    reason: str = ""

    @property
    def where(self) -> str:
        return f"{self.page.relative_to(ROOT)}:{self.line}"


def blocks(page: Path) -> list[Block]:
    """The fenced code blocks of a Markdown page, with the ``<!-- snippet: ... -->`` mark of the
    line before each (blank lines between allowed)."""
    lines = page.read_text(encoding="utf-8").splitlines()
    out: list[Block] = []
    i = 0
    while i < len(lines):
        m = FENCE.match(lines[i])
        if not m:
            i += 1
            continue
        ticks, lang = m["ticks"], m["lang"]
        j = i + 1
        while j < len(lines) and not lines[j].lstrip().startswith(ticks):
            j += 1
        k = i - 1
        while k >= 0 and not lines[k].strip():
            k -= 1
        mark = MARK.search(lines[k]) if k >= 0 else None
        code = textwrap.dedent("\n".join(lines[i + 1 : j])) + "\n"
        out.append(
            Block(
                page,
                i + 2,
                lang,
                code,
                mark["kind"] if mark else "",
                mark["reason"] if mark else "",
            )
        )
        i = j + 1
    return out


def python_pages() -> list[Path]:
    return [p for p in PAGES if any(b.lang == "python" for b in blocks(p))]


# --- the runner, executed in the subprocess ------------------------------------------------------

RUNNER = r"""
# under a guard: a snippet that starts processes (Dask's nanny, multiprocessing spawn)
# re-imports this file as __mp_main__ in the child
import json, sys, time, traceback


def main():
    blocks = json.load(open(sys.argv[1], encoding="utf-8"))
    ns = {"__name__": "__main__"}
    failed = []
    for b in blocks:
        if b["fresh"]:
            ns = {"__name__": "__main__"}
        code = "\n" * (b["line"] - 1) + b["code"]
        print(f"=== {b['page']}:{b['line']}", flush=True)
        t0 = time.perf_counter()
        try:
            exec(compile(code, b["page"], "exec"), ns)
        except BaseException:
            if b["mark"] == "xfail":
                print(f"--- expected failure ({b['reason']}):", flush=True)
                traceback.print_exc(file=sys.stdout)
                continue
            traceback.print_exc()
            failed.append(f"{b['page']}:{b['line']}")
            break
        else:
            if b["mark"] == "xfail":
                failed.append(f"{b['page']}:{b['line']} (marked xfail, but it ran: {b['reason']})")
                break
        print(f"=== {b['page']}:{b['line']} took {time.perf_counter() - t0:.1f} s", flush=True)
    if failed:
        print("FAILED:", *failed, file=sys.stderr)
        sys.exit(1)


if __name__ == "__main__":
    main()
"""


def _env() -> dict:
    env = dict(os.environ)
    env.pop("ANTHROARM_CACHE", None)  # the default cache folder, as a user has it
    env["MPLBACKEND"] = "Agg"
    env["PYTHONUNBUFFERED"] = "1"
    return env


def run_page(page: Path, cwd: Path) -> subprocess.CompletedProcess:
    todo = [
        {
            "page": str(b.page.relative_to(ROOT)),
            "line": b.line,
            "code": b.code,
            "mark": b.mark,
            "reason": b.reason,
            "fresh": page in SELF_CONTAINED,
        }
        for b in blocks(page)
        if b.lang == "python" and b.mark != "skip"
    ]
    (cwd / "_blocks.json").write_text(json.dumps(todo), encoding="utf-8")
    (cwd / "_run_blocks.py").write_text(RUNNER, encoding="utf-8")
    return subprocess.run(
        [sys.executable, "_run_blocks.py", "_blocks.json"],
        cwd=cwd,
        env=_env(),
        capture_output=True,
        text=True,
        timeout=PAGE_TIMEOUT,
    )


# --- shell blocks --------------------------------------------------------------------------------

#: commands that run long (the cross-check of a whole robot, a 10⁷-sample batch job, a cluster
#: job): their arguments are parsed by the CLI's own parser, the command is not run
SLOW_COMMANDS = ("anthroarm bench", "anthroarm batch", "anthroarm check")


def commands(page: Path) -> list[tuple[str, str]]:
    """(where, command) of every ``anthroarm ...`` line of the page's shell blocks (a line
    ending in a backslash continues on the next)."""
    out = []
    for b in blocks(page):
        if b.lang not in {"bash", "sh", "console"} or b.mark == "skip":
            continue
        lines = b.code.splitlines()
        n = 0
        while n < len(lines):
            first = n
            cmd = lines[n].strip()
            while cmd.endswith("\\") and n + 1 < len(lines):
                n += 1
                cmd = cmd[:-1] + " " + lines[n].strip()
            n += 1
            cmd = cmd.removeprefix("$ ")
            if cmd.startswith("anthroarm "):
                out.append((f"{b.page.relative_to(ROOT)}:{b.line + first}", cmd))
    return out


def _parse_only(argv: list[str]) -> bool:
    """A command that serves a live viewer until interrupted (``view``/``teach`` without
    ``--html``), or a long one (:data:`SLOW_COMMANDS`)."""
    live = argv[1] in {"view", "teach"} and "--html" not in argv
    return live or any(" ".join(argv).startswith(s) for s in SLOW_COMMANDS)


def parse_commands(cmds: list[str], cwd: Path) -> subprocess.CompletedProcess:
    """Parse each command with the CLI's own parser (one process for all), without running it."""
    argvs = [shlex.split(c, comments=True)[1:] for c in cmds]
    code = (
        "import sys\nfrom anthroarm import cli\n"
        f"for argv in {argvs!r}:\n"
        "    a, extras = cli.build_parser(argv).parse_known_args(argv)\n"
        "    if extras:\n"
        "        sys.exit(f'anthroarm {\" \".join(argv)}: unrecognized arguments: {extras}')\n"
    )
    return subprocess.run(
        [sys.executable, "-c", code],
        cwd=cwd,
        env=_env(),
        capture_output=True,
        text=True,
        timeout=COMMAND_TIMEOUT,
    )


def run_command(cmd: str, cwd: Path) -> subprocess.CompletedProcess:
    exe = shutil.which("anthroarm", path=str(Path(sys.executable).parent)) or "anthroarm"
    argv = [exe, *shlex.split(cmd, comments=True)[1:]]
    return subprocess.run(
        argv, cwd=cwd, env=_env(), capture_output=True, text=True, timeout=COMMAND_TIMEOUT
    )


def _earlier(page: Path, cmd: str) -> bool:
    """The same command on an earlier page (it ran there; here it is only parsed)."""
    argv = shlex.split(cmd, comments=True)
    return any(
        shlex.split(c, comments=True) == argv
        for p in PAGES[: PAGES.index(page)]
        for _, c in commands(p)
    )


def pages() -> list[Path]:
    return [
        p
        for p in PAGES
        if commands(p) or any(b.lang == "python" and b.mark != "skip" for b in blocks(p))
    ]


@pytest.mark.parametrize("page", pages(), ids=lambda p: str(p.relative_to(ROOT)))
def test_page_runs(page, tmp_path):
    """The page's Python blocks in order in one namespace, then its ``anthroarm`` commands, in
    one temporary folder (a command may read what a block wrote: a C3D trial)."""
    where = page.relative_to(ROOT)
    if any(b.lang == "python" for b in blocks(page)):
        r = run_page(page, tmp_path)
        assert r.returncode == 0, f"{where}:\n{r.stdout[-4000:]}\n{r.stderr[-6000:]}"
    parse = []
    for line, cmd in commands(page):
        if _parse_only(shlex.split(cmd, comments=True)) or _earlier(page, cmd):
            parse.append(cmd)
            continue
        r = run_command(cmd, tmp_path)
        assert r.returncode == 0, f"{line}: {cmd}\n{r.stdout[-3000:]}\n{r.stderr[-3000:]}"
    if parse:
        r = parse_commands(parse, tmp_path)
        assert r.returncode == 0, f"{where}: {r.stdout[-3000:]}\n{r.stderr[-3000:]}"


# --- numbers quoted from the committed benchmark tables -----------------------------------------


def table(name: str) -> list[dict]:
    """The rows of the first markdown table of ``benchmarks/results/NAME``, as dicts."""
    rows = [
        [c.strip() for c in line.strip().strip("|").split("|")]
        for line in (RESULTS / name).read_text(encoding="utf-8").splitlines()
        if line.startswith("|")
    ]
    head = rows[0]
    return [dict(zip(head, r)) for r in rows[2:]]


def cell(rows: list[dict], column: str, **match) -> float:
    """The number in ``column`` of the one row whose cells start with the ``match`` values."""
    hits = [r for r in rows if all(r[k].startswith(v) for k, v in match.items())]
    assert len(hits) == 1, f"{match}: {len(hits)} rows"
    return float(hits[0][column])


def span(values, fmt: str = "{:.2f}") -> str:
    """'lo–hi' as the pages write a range."""
    return f"{fmt.format(min(values))}–{fmt.format(max(values))}"


def _page(rel: str) -> str:
    return " ".join((ROOT / rel).read_text(encoding="utf-8").split())


def quotes() -> list[tuple[str, str]]:
    """(page, text it must contain), each text made from a committed table."""
    out = []
    viewer = table("viewer.md")
    fps = cell(viewer, "fps", model="human_arm7", path="batched (anthroarm)")
    per_link = cell(viewer, "fps", model="human_arm7", path="one message per link")
    head = (RESULTS / "viewer.md").read_text(encoding="utf-8")
    packed = re.search(r"([\d.]+) MB with the meshes packed", head)[1]
    raw = re.search(r"([\d.]+) MB with the mesh files as they are", head)[1]
    out += [
        ("README.md", f"all link transforms in one message ({fps:.0f} poses/s"),
        ("README.md", f"| {fps:.0f} poses/s (one message a pose)"),
        ("README.md", f"meshcat-python style {per_link:.0f}/s"),
        ("README.md", f"{float(packed):.1f} MB (was {raw} MB)"),
        ("docs/guide/viewer.md", f"went from {raw} MB to {packed} MB"),
    ]
    hand = table("hand.md")
    step = "qp step (6 frame"
    us = {
        b: (
            cell(hand, "ours median", measure=step, backend=b),
            cell(hand, "peer median", measure=step, backend=b),
            cell(hand, "ratio peer/ours", measure=step, backend=b),
        )
        for b in ("daqp", "quadprog", "proxqp", "osqp")
    }
    mink = [
        cell(hand, "peer median", measure="qp step vs mink", backend=b)
        for b in ("daqp", "quadprog")
    ]
    grasp = [
        cell(hand, c, measure="grasp solve (given contacts")
        for c in ("ours median", "peer median", "pink success %")
    ]
    allegro = [
        cell(hand, c, measure="grasp solve (sliding") for c in ("ours median", "peer median")
    ]
    d, q, x, o = us["daqp"], us["quadprog"], us["proxqp"], us["osqp"]
    out += [
        ("docs/guide/grasp.md", f"| {d[0]:.0f} µs | {d[1]:.0f} µs ({d[2]:.1f}×) |"),
        (
            "docs/guide/grasp.md",
            f"| {q[0]:.0f} / {x[0]:.0f} / {o[0]:.0f} µs | {q[1]:.0f} / {x[1]:.0f} / {o[1]:.0f} µs "
            f"({q[2]:.1f}× / {x[2]:.1f}× / {o[2]:.1f}×) |",
        ),
        ("docs/guide/grasp.md", f"| {grasp[0]:.0f} ms, 100 % | {grasp[1]:.0f} ms, {grasp[2]} % |"),
        ("docs/guide/grasp.md", f"| {allegro[0]:.0f} ms, 100 % | {allegro[1]:.0f} ms, 100 % |"),
        ("docs/guide/grasp.md", f"takes {span(mink, '{:.0f}')} µs with daqp or quadprog"),
        (
            "README.md",
            f"| {d[0]:.0f} µs; 500 grasps 100 % in {grasp[0]:.0f} ms | pink {d[1]:.0f} µs "
            f"({d[2]:.1f}×), mink {mink[0]:.0f} µs",
        ),
        ("README.md", f"pink grasps {grasp[2]} % in {grasp[1]:.0f} ms"),
    ]
    emg = table("emg.md")
    ours = cell(emg, "median ms per 1 s of EMG", pipeline="ours: EMGProcessor (RMS")
    nk = cell(emg, "median ms per 1 s of EMG", pipeline="neurokit2: emg_process")
    out += [("README.md", f"| {ours:.2f} ms ("), ("README.md", f"`emg_process` {nk:.0f} ms")]
    mik = table("marker_ik.md")
    ours = [float(r["ours ms/frame"]) for r in mik if r["backend"] != "osqp"]
    scipy = [float(r["scipy ms/frame"]) for r in mik]
    out += [
        ("README.md", f"| {span(ours)} ms/frame"),
        ("README.md", f"`least_squares` {span(scipy, '{:.1f}')} ms"),
        ("docs/guide/motion.md", f"{span(ours)} ms a frame"),
        ("docs/guide/motion.md", f"warm-started, {span(scipy, '{:.1f}')} ms"),
    ]
    return out


def test_quoted_numbers_match_the_committed_tables():
    missing = [f"{page}: {text!r}" for page, text in quotes() if text not in _page(page)]
    assert not missing, "quoted numbers that differ from benchmarks/results:\n" + "\n".join(missing)
