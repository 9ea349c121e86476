"""The sizing report a prosthetist would hand a colleague (issue 31 item 5).

* every weight rule is explained in words, with its line of the book quoted as printed (the
  lines below are copied from the book's OCR text, 000_f79f72c676d090fb.txt; the code's quotes
  must be part of them);
* the report's verdict and ``anthroarm size``'s JSON list the same things that did not fit;
* the date, the inputs and the package version are in it, no local path is;
* the plots' text is at least 11 px; the motor's whole torque–speed line is inside the axes;
* the body masses are the model's, the small connecting bodies said to be so;
* in headless Chromium at A4 print size nothing is wider than the page (browser mark).
"""

from __future__ import annotations

import base64
import html
import json
import re
from pathlib import Path

import numpy as np
import pytest

import anthroarm as aa
from anthroarm import __version__
from anthroarm.cli import main
from anthroarm.dynamics.hand_model import minimum_jerk
from anthroarm.prosthesis import report, study
from anthroarm.prosthesis.weight_rules import RULE_TEXTS

#: The book's lines as printed (000_f79f72c676d090fb.txt, line -> text).
BOOK_LINES = {
    274: "显然,多自由度与轻量化的要求是相互制约的。通常假手动力装置和减速机构部分的重量往往要"
    "占重量的50~60%。为此,研制小型、高效、大输出的驱动装置是开发全臂电动假手的一个关键问题。",
    7298: "人的(双)臂重约为本身体重的12.6%,若从这点出发,全臂假手的重可为4~5 kg左右。",
    7441: "为了使全臂假手能以空间物体所具有的六个自由度自由地操作,近似地实现人手那样的动作,"
    "必须确保假手至少有七个自由度,即肩部3个、肘部1个、前臂2个、手部1个。",
    7445: "- (1) 臂重要轻,要求不大于2 kg;",
}


@pytest.fixture(scope="module")
def person():
    return aa.load("human_arm7", height=1.75, mass=70.0, sex="male")


def reach(person):
    """A 1 s minimum-jerk reach (shoulder and elbow), t and q."""
    t = np.linspace(0, 1.0, 51)
    q0 = person.neutral()
    q, _, _ = minimum_jerk(q0, q0 + np.array([1.2, -0.3, 0.2, 1.4, 0.5, 0.1, 0.3]), 1.0, t)
    return t, q


@pytest.fixture(scope="module")
def st(person):
    t, q = reach(person)
    acts = [dict(name="reach", t=t, q=q), dict(name="back", t=t, q=q[::-1].copy())]
    return study.run(person, acts, payload=0.5, person=dict(height=1.75, mass=70.0, sex="male"))


@pytest.fixture(scope="module")
def text(st):
    return report.render(st)


def test_every_rule_is_explained_with_its_book_line(st, text):
    assert {r.source for r in st.rules} <= set(RULE_TEXTS)
    for r in st.rules:
        t = RULE_TEXTS[r.source]
        line = int(r.source[1:])
        assert t.quote.rstrip("。;") in BOOK_LINES[line], r.source
        assert len(t.words.split()) > 15  # words, not an id
        assert f"Book, line {line}: {html.escape(t.quote)}" in text
        assert html.escape(t.words) in text


def test_the_verdict_is_the_jsons(st, text, tmp_path, capsys):
    unfit = st.unfit()
    failed = [r.source for r in st.rules if r.ok is False]
    assert failed, "the 2-activity study should fail a weight rule (the drive is > 1.2 kg)"
    assert [u["name"] for u in unfit if u["what"] == "rule"] == failed
    verdict = text[text.index("class='verdict") : text.index("The person's arm model")]
    for u in unfit:
        assert f"<b>{u['name']}</b>" in verdict
    # the CLI's JSON: the same list, as the report of the same run shows it
    out = tmp_path / "r.html"
    t, q = reach(st.robot)
    np.savez(tmp_path / "reach.npz", t=t, q=q)
    np.savez(tmp_path / "back.npz", t=t, q=q[::-1].copy())
    files = f"{tmp_path / 'reach.npz'},{tmp_path / 'back.npz'}"
    rc = main(
        ["size", "--activities", files, "--payload", "0.5", "--mass", "70"]
        + ["--no-viewer", "--no-progress", "-o", str(out)]
    )
    assert rc == 0
    summary = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    page = out.read_text(encoding="utf-8")
    verdict = page[page.index("class='verdict") : page.index("The person's arm model")]
    assert summary["unfit"] == [
        u if u["what"] != "activity" else {**u, "name": u["name"]} for u in unfit
    ]
    assert [s for s in re.findall(r"<b>([^<]+)</b>", verdict)] == [u["name"] for u in unfit]


def test_date_inputs_version_and_no_local_path(st, text):
    assert re.search(r"\d{4}-\d\d-\d\d \d\d:\d\d UTC", text)
    assert f"anthroarm {__version__}" in text
    for needle in ("1.75 m", "70.0 kg", "male", "motors.csv", "gearboxes.csv", "0.5 kg"):
        assert needle in text, needle
    root = str(Path(aa.__file__).resolve().parents[1])
    assert root not in text and "site-packages" not in text and "/home/" not in text


def test_body_masses_are_the_models(person, text):
    section = text[text.index("The person's arm model") : text.index("<h2>Activities")]
    rows = re.findall(r"<tr><td class=\"l\">(\w+)</td>(.*?)</tr>", section)
    masses = {}
    for name, rest in rows:
        cells = re.findall(r"<td[^>]*>([^<]*)</td>", rest)
        if name in person.joint_names and len(cells) >= 5:
            masses[name] = (float(cells[2].rstrip(" *")), float(cells[3]), cells[2].endswith("*"))
    model = person.model
    for j in person.chain.joints:
        body, moved, starred = masses[j.name]
        assert body == pytest.approx(model.inertias[j.index + 1].mass, abs=5e-4)
        sub = [k for k in range(j.index + 1, model.njoints) if j.index + 1 in model.supports[k]]
        assert moved == pytest.approx(sum(model.inertias[k].mass for k in sub), abs=5e-3)
        assert starred == (body < 0.1)
    assert "small connecting bodies" in text


def test_plots_are_legible_and_hold_the_motor_line(st):
    for j in range(len(st.envelope.joint_names)):
        fig = report.joint_figure(st, j)
        texts = [
            t
            for t in fig.findobj(lambda o: hasattr(o, "get_fontsize") and hasattr(o, "get_text"))
            if t.get_text()
        ]
        px = min(t.get_fontsize() for t in texts) * report.PLOT_DPI / 72
        assert px >= 11, (j, px)
        ax = fig.axes[1]
        line = ax.get_lines()[len(st.envelope.activities)]  # the torque-speed line
        x, y = (np.asarray(v, float) for v in line.get_data())
        (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
        assert x0 <= x.min() and x.max() <= x1 and y0 <= y.min() + 1e-9 and y.max() <= y1, j
        assert y.max() > 0 and x.max() > 0


def test_print_stylesheet(text):
    assert "@page { size: A4" in text and "@media print" in text


@pytest.mark.browser
def test_the_report_fits_an_a4_page_in_chromium(text, tmp_path):
    """At A4 print size (the page's width less the margins, 96 px/in) nothing is wider than the
    page, every plot is shown at least at 90 % of its size, and Chromium prints a few pages."""
    from anthroarm.viewer import browser

    if browser.find_chromium() is None:
        pytest.skip("chromium is not installed (Debian: apt-get install chromium)")
    html = tmp_path / "report.html"
    html.write_text(text, encoding="utf-8")
    width = round((210 - 24) / 25.4 * 96)  # A4 less the 12 mm margins of @page
    with browser.live_tab("about:blank", size=(width, 1000)) as tab, browser.DevTools(tab) as p:
        p.call("Emulation.setEmulatedMedia", media="print")
        p.call(
            "Emulation.setDeviceMetricsOverride",
            width=width,
            height=1000,
            deviceScaleFactor=1,
            mobile=False,
        )
        p.call("Page.navigate", url=html.resolve().as_uri())
        p.wait_for("document.readyState === 'complete' && document.images.length > 0")
        got = json.loads(
            p.evaluate(
                "JSON.stringify({sw: document.documentElement.scrollWidth,"
                " imgs: Array.from(document.images).map(i => [i.naturalWidth, i.width])})"
            )
        )
        pdf = base64.b64decode(
            p.call("Page.printToPDF", preferCSSPageSize=True, printBackground=False)["data"]
        )
    assert got["sw"] <= width, got["sw"]
    assert got["imgs"] and all(w >= 0.9 * n for n, w in got["imgs"]), got["imgs"]
    pages = pdf.count(b"/Type /Page") - pdf.count(b"/Type /Pages")
    assert 2 <= pages <= 12, pages
