"""A self-contained HTML report of a sizing :class:`~.study.Study`.

One file, no network, to hand a colleague: the date, the package version and the inputs; the
verdict (what did not fit: :meth:`~.study.Study.unfit`, the same list ``anthroarm size`` prints
as JSON); the person's model (segments, masses, joint ranges); the activities, optionally
animated in the meshcat viewer (``viewer``: the page of
:func:`anthroarm.viewer.pages.activities_html`, embedded once as an ``<iframe srcdoc>``); the
envelope; the chosen motors and gearboxes and the drive mass; the book's weight rules, each
explained in words with its line of the book (:data:`~.weight_rules.RULE_TEXTS`); per joint the
torque–time curves and the (speed, torque) points of every activity under the chosen motor's
whole torque–speed line and continuous-torque limit (PNG, base64, text ≥ 11 px); the catalogues
by file name (no local path).  A print stylesheet lays it out on A4 (``@media print``).
Written atomically (:func:`anthroarm._io.atomic_write_text`).
"""

from __future__ import annotations

import base64
import datetime
import html
import io
from pathlib import Path

import numpy as np

from .. import __version__
from .._io import atomic_write_text
from ..errors import ParameterError
from .catalogue import source_note
from .envelope import CUP_HEIGHT, CUP_RADIUS
from .weight_rules import RULE_TEXTS

#: Font sizes of the plots, points; at :data:`PLOT_DPI` a point is 100/72 px, so 8 pt = 11.1 px.
PLOT_FONT = {"small": 8.5, "normal": 9.5}
PLOT_DPI = 100

_CSS = """
body { font-family: system-ui, sans-serif; margin: 1.5em auto; max-width: 1100px; color: #222;
       padding: 0 1em; }
h1 { font-size: 1.5em; } h2 { font-size: 1.2em; margin-top: 1.6em; border-bottom: 1px solid #ccc; }
table { border-collapse: collapse; margin: 0.6em 0; font-size: 0.9em; }
th, td { border: 1px solid #ccc; padding: 3px 8px; text-align: right; vertical-align: top; }
th { background: #f0f2f5; } td.l, th.l { text-align: left; }
.ok { color: #1a7f37; } .bad { color: #c62828; font-weight: bold; } .info { color: #555; }
.note { color: #555; font-size: 0.85em; } img { max-width: 100%; height: auto; }
.quote { color: #444; font-size: 0.9em; }
.verdict { border: 2px solid #c62828; padding: 0.4em 1em; } .verdict.fits { border-color: #1a7f37; }
iframe { width: 100%; height: 480px; border: 1px solid #ccc; }
@page { size: A4; margin: 14mm 12mm; }
@media print {
  body { max-width: none; margin: 0; padding: 0; font-size: 9.5pt; }
  h2 { break-after: avoid; page-break-after: avoid; }
  table, img, .joint, .verdict { break-inside: avoid; page-break-inside: avoid; }
  iframe, .screen { display: none; }
  a { color: inherit; text-decoration: none; }
}
"""


def _e(x) -> str:
    return html.escape(str(x), quote=True)


def _table(header, rows, left=(0,)) -> str:
    h = "".join(
        f'<th class="{"l" if i in left else ""}">{_e(c)}</th>' for i, c in enumerate(header)
    )
    body = []
    for r in rows:
        cells = []
        for i, c in enumerate(r):
            cls = "l" if i in left else ""
            if isinstance(c, tuple):  # (text, css class)
                c, extra = c
                cls = f"{cls} {extra}".strip()
            cells.append(f'<td class="{cls}">{_e(c)}</td>')
        body.append("<tr>" + "".join(cells) + "</tr>")
    return f"<table><tr>{h}</tr>{''.join(body)}</table>"


def _png(fig, dpi: int = PLOT_DPI) -> str:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)  # constrained layout: no second (tight) pass
    return (
        '<img alt="plot" src="data:image/png;base64,'
        + base64.b64encode(buf.getvalue()).decode("ascii")
        + f'" width="{int(fig.get_figwidth() * dpi)}">'
    )


def joint_figure(study, j: int):
    """The figure of joint ``j``: τ(t) of every usable activity, and its (|q̇|, |τ|) points over
    the chosen (or closest) motor + gearbox's torque–speed line at the nominal voltage
    (Eq. (9-1) through the gearbox, :meth:`anthroarm.control.motor.DCMotor.joint_torque`) and its
    continuous torque η i τ_cont.  Returns a :class:`matplotlib.figure.Figure` (no pyplot state)."""
    from matplotlib.figure import Figure

    env, js = study.envelope, study.sizing.joints[j]
    name = env.joint_names[j]
    small, normal = PLOT_FONT["small"], PLOT_FONT["normal"]
    # 7.2 in at 100 dpi = 720 px: shown at its size on screen and about so on an A4 page
    fig = Figure(figsize=(7.2, 3.9), layout="constrained")
    a0, a1 = fig.subplots(1, 2)
    scale = 1.0 + study.sizing.margin
    wmax, tmax = 0.0, 0.0
    for act in env.activities:
        a0.plot(act.t - act.t[0], act.tau[:, j], lw=1.2, label=act.name)
        a1.plot(np.abs(act.qd[:, j]), np.abs(act.tau[:, j]), ".", ms=3)
        wmax = max(wmax, float(np.max(np.abs(act.qd[:, j]))))
        tmax = max(tmax, float(np.max(np.abs(act.tau[:, j]))))
    a0.set_xlabel("t [s]", fontsize=normal)
    a0.set_ylabel(f"{name} torque [N m]", fontsize=normal)
    a0.axhline(0, color="k", lw=0.5)
    fig.legend(
        *a0.get_legend_handles_labels(),
        loc="outside lower center",
        ncol=4,
        fontsize=small,
        frameon=False,
    )
    cand = js.choice or js.closest
    wtop, ttop = max(wmax * scale, 1e-3), max(tmax * scale, 1e-3)
    if cand is not None:
        dc = cand.dc_motor()
        w0 = float(dc.no_load_speed())
        w = np.linspace(0.0, w0, 200)
        line = dc.joint_torque(w)
        a1.plot(w, line, "k-", lw=1.5, label=f"torque-speed line, {dc.V_nom:g} V (9-1)")
        a1.axhline(dc.continuous_torque, color="tab:red", ls="--", lw=1, label="motor continuous")
        a1.axhline(
            cand.gearbox.tau_max, color="tab:purple", ls=":", lw=1, label="gearbox intermittent"
        )
        # the whole line inside the axes: from the stall torque at 0 to the no-load speed
        wtop = max(wtop, w0)
        ttop = max(ttop, float(np.max(line)), cand.gearbox.tau_max, dc.continuous_torque)
        a1.set_title(("" if js.choice else "closest, does not fit: ") + cand.name, fontsize=normal)
    a1.set_xlim(0, wtop * 1.05)
    a1.set_ylim(0, ttop * 1.08)
    zw, zt = max(wmax * scale, 1e-3) * 1.15, max(tmax * scale, 1e-3) * 1.15
    if zw < 0.5 * wtop or zt < 0.5 * ttop:  # the demands are a corner of the motor's range
        z = a1.inset_axes((0.42, 0.1, 0.5, 0.42))
        for act in env.activities:
            z.plot(np.abs(act.qd[:, j]), np.abs(act.tau[:, j]), ".", ms=2)
        for line2d in a1.get_lines()[len(env.activities) :]:
            z.plot(*line2d.get_data(), ls=line2d.get_linestyle(), color=line2d.get_color(), lw=1)
        z.set_xlim(0, zw)
        z.set_ylim(0, zt)
        z.tick_params(labelsize=small)
        z.set_title("the demands, enlarged", fontsize=small)
        a1.indicate_inset_zoom(z, edgecolor="0.4")
    a1.set_xlabel(f"|{name} speed| [rad/s]", fontsize=normal)
    a1.set_ylabel("|torque| [N m]", fontsize=normal)
    a1.legend(fontsize=small, loc="upper right")
    for ax in (a0, a1):
        ax.tick_params(labelsize=small)
    return fig


def _ancestors(chain, k: int) -> set:
    """Joint ``k`` and every joint between it and the base."""
    out = set()
    while k >= 0:
        out.add(k)
        k = chain.joints[k].parent
    return out


def _person_section(study) -> str:
    robot = study.robot
    chain = robot.chain
    p = study.person
    rows = []
    total = sum(j.mass for j in chain.joints)
    tiny = [j.name for j in chain.joints if j.mass < 0.01 * max(total, 1e-9) * 2]
    for j in chain.joints:
        moved = sum(k.mass for k in chain.joints if j.index in _ancestors(chain, k.index))
        rows.append(
            (
                j.name,
                j.kind,
                np.array2string(np.round(j.axis, 3), separator=", "),
                f"{j.mass:.3f}" + (" *" if j.name in tiny else ""),
                f"{moved:.3f}",
                f"{np.linalg.norm(j.translation):.3f}",
                f"{np.degrees(j.lower):.0f}",
                f"{np.degrees(j.upper):.0f}",
            )
        )
    who = ", ".join(
        f"{k} {v}" + (" m" if k == "height" else " kg" if k == "mass" else "") for k, v in p.items()
    )
    spec = dict(robot.spec.params) if robot.spec is not None else {}
    extra = ", ".join(
        f"{k} = {v:.3f} m" for k, v in spec.items() if k not in p and isinstance(v, float)
    )
    note = (
        "<p class='note'>* "
        + ", ".join(tiny)
        + ": the model's small connecting bodies between joints that share a point (the "
        "shoulder's three axes, the elbow and the forearm's rotation, the wrist's two): each "
        "segment's mass (de Leva 1996) sits on the last joint of its group.  'Mass it moves' is everything distal of the joint, the "
        "load its motor carries (the held object comes on top).</p>"
        if tiny
        else ""
    )
    return (
        f"<h2>The person's arm model</h2><p>{_e(robot.name)} ({robot.nv} joints) for {_e(who)}"
        + (f" ({_e(extra)})" if extra else "")
        + f"; arm mass {total:.2f} kg, reach {chain.reach():.3f} m; "
        f"held object: a solid cylinder (r = {CUP_RADIUS * 100:g} cm, h = {CUP_HEIGHT * 100:g} cm) at the hand point"
        + (f", at least {study.payload:g} kg" if study.payload > 0 else "")
        + "; its largest mass in each activity is in the activities' table.</p>"
        + _table(
            [
                "joint",
                "kind",
                "axis (joint frame)",
                "body mass [kg]",
                "mass it moves [kg]",
                "offset from parent [m]",
                "lower [deg]",
                "upper [deg]",
            ],
            rows,
            left=(0, 1, 2),
        )
        + note
    )


def _fmt_ok(ok):
    if ok is None:
        return ("info", "info")
    return ("yes", "ok") if ok else ("NO", "bad")


def _header(study, inputs, when) -> str:
    """The date, the package version and the inputs (no local path: files by name)."""
    given = dict(inputs or {})
    given.setdefault("model", study.robot.name)
    for k, v in study.person.items():
        given.setdefault(k, v)
    given.setdefault("activities", ", ".join(a.name for a in study.activities))
    given.setdefault("payload_kg", study.payload)
    given.setdefault("margin", study.sizing.margin)
    given["motor catalogue"] = Path(study.catalogue.motor_source or "-").name
    given["gearbox catalogue"] = Path(study.catalogue.gearbox_source or "-").name
    units = {"height": " m", "mass": " kg", "payload_kg": " kg"}
    rows = [
        (k.replace("_kg", ""), "-" if v is None else f"{v}{units.get(k, '')}")
        for k, v in given.items()
    ]
    return (
        f"<p class='note'>{_e(when.strftime('%Y-%m-%d %H:%M UTC'))} · anthroarm "
        f"{_e(__version__)} · <code>anthroarm size</code></p>"
        + "<h2>Inputs</h2>"
        + _table(["input", "value"], rows, left=(0, 1))
    )


def _verdict(study) -> str:
    """What did not fit (:meth:`~.study.Study.unfit`, the JSON's list), first."""
    unfit = study.unfit()
    if not unfit:
        return (
            "<div class='verdict fits'><h2>Verdict</h2><p>Everything fits: every joint has a "
            "motor and gearbox, every activity is in the envelope, every weight rule is met."
            "</p></div>"
        )
    items = "".join(
        f"<li>{_e(u['what'])} <b>{_e(u['name'])}</b>: {_e(u['reason'])}</li>" for u in unfit
    )
    return (
        f"<div class='verdict'><h2>Verdict: {len(unfit)} thing(s) did not fit</h2>"
        f"<ul>{items}</ul><p class='note'>The same list as the <code>unfit</code> entry of "
        "<code>anthroarm size</code>'s JSON; the rules are explained below.</p></div>"
    )


def render(
    study,
    *,
    viewer=None,
    title: str | None = None,
    inputs: dict | None = None,
    when: datetime.datetime | None = None,
) -> str:
    """The report's HTML text (see the module docstring).

    ``viewer``: the animation to embed, an HTML fragment made by
    :func:`anthroarm.viewer.pages.activities_html` (``None`` or ``False``: none, and no
    meshcat JavaScript in the file).  ``inputs``: the inputs to list (the CLI's options;
    default: the study's person, activities, payload, margin); ``when``: the date shown
    (default now, UTC)."""
    if viewer is True:
        raise ParameterError(
            "report.render(viewer=...) takes the animation's HTML: "
            "viewer=anthroarm.viewer.pages.activities_html(study) (the report does not import "
            "the viewer), or None"
        )
    when = when or datetime.datetime.now(datetime.timezone.utc)
    env, sz = study.envelope, study.sizing
    parts = [
        f"<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>"
        f"<title>{_e(title or 'anthroarm prosthesis sizing')}</title>"
        f"<style>{_CSS}</style></head><body>",
        f"<h1>{_e(title or 'From a person to a prosthesis: joint demands and motors')}</h1>",
        _header(study, inputs, when),
        _verdict(study),
    ]
    parts.append(_person_section(study))
    # activities
    arows = []
    for a in study.activities:
        ok = a.status == "ok"
        arows.append(
            (
                a.name,
                f"{a.duration:.2f}" if len(a.t) else "",
                len(a.t),
                f"{a.payload:g}",
                (a.status, "ok" if ok else "bad"),
                a.reason,
            )
        )
    parts.append(
        "<h2>Activities</h2>"
        + _table(
            ["activity", "duration [s]", "samples", "max payload [kg]", "status", "reason"],
            arows,
            left=(0, 4, 5),
        )
    )
    if viewer:
        parts.append(str(viewer))
    # envelope
    erows = [
        (
            r["joint"],
            f"{r['peak_torque']:.2f}",
            f"{r['rms_torque']:.2f}",
            f"{r['peak_speed']:.2f}",
            f"{r['peak_power']:.2f}",
        )
        for r in env.rows()
    ]
    parts.append(
        "<h2>Envelope over the activities</h2>"
        + _table(
            [
                "joint",
                "peak |torque| [N m]",
                "RMS torque [N m]",
                "peak |speed| [rad/s]",
                "peak |power| [W]",
            ],
            erows,
        )
        + '<p class="note">Torques from the Lagrange equations with the held object as a wrench at the '
        "hand (Eq. (8-5)), equal to Pinocchio's rnea with fext (tests/dynamics/test_loads.py). RMS: "
        "the largest over the activities of sqrt(integral tau^2 dt / T).</p>"
    )
    if study.muscles():
        mrows = [
            (
                r["joint"],
                f"{r['peak_demand']:.2f}",
                f"{r['peak_muscle']:.2f}",
                f"{r['peak_motor']:.2f}",
                f"{r['covered']:.0%}",
            )
            for r in study.muscles()
        ]
        parts.append(
            "<h2>Residual muscles and motors</h2>"
            + _table(
                [
                    "joint",
                    "peak demand [N m]",
                    "peak muscle torque [N m]",
                    "peak motor torque [N m]",
                    "share covered by muscles",
                ],
                mrows,
            )
            + '<p class="note">The person\'s remaining muscles (OpenSim model, Thelen2003 forces with '
            "the tendon at slack length, times the strength factor) cover the torque closest to the "
            "demand that activations in [0, 1] reach (anthroarm.prosthesis.residual); the envelope "
            "above and the motors below are for the rest.</p>"
        )
    # sizing
    srows = []
    for r, js in zip(sz.rows(), sz.joints):
        ok = r["status"] == "ok"
        srows.append(
            (
                r["joint"],
                (r["status"], "ok" if ok else "bad"),
                r["motor"] or "-",
                r["gearbox"] or "-",
                f"{r['ratio']:g}" if ok else "-",
                f"{r['mass'] * 1e3:.0f}" if ok else "-",
                r["limiting"],
                f"{r['utilisation']:.2f}",
            )
        )
    parts.append(
        f"<h2>Chosen motors and gearboxes (margin {sz.margin:.0%})</h2>"
        + _table(
            [
                "joint",
                "status",
                "motor",
                "gearbox",
                "ratio",
                "mass [g]",
                "limiting check",
                "utilisation",
            ],
            srows,
            left=(0, 1, 2, 3, 6),
        )
        + f"<p><b>Drive mass (motors + gearboxes): {sz.drive_mass:.3f} kg</b>"
        + (f", {len(sz.unfit)} joint(s) without a motor" if sz.unfit else "")
        + "</p>"
        + '<p class="note">Servo model of Eq. (9-1) through the gearbox (anthroarm.control.motor.DCMotor); '
        "a pair covers a joint when every sample of every activity, times (1 + margin), lies under the "
        "torque-speed line at the nominal voltage (rotor inertia included), the RMS motor torque is "
        "within the rated continuous torque, the gearbox's intermittent and continuous torques and the "
        "speed limits hold; the lightest such pair is chosen.</p>"
    )
    # weight rules, each in words with its line of the book
    wrows = []
    for r in study.rules:
        wrows.append(
            (
                r.source,
                r.rule,
                f"{r.value:.2f}",
                f"{r.limit:.2f}",
                r.unit,
                _fmt_ok(r.ok),
                r.note,
            )
        )
    explained = "".join(
        f"<li><b>{_e(t.source)}</b>: {_e(t.words)}<br><span class='quote'>Book, line "
        f"{_e(t.source[1:])}: {_e(t.quote)} — {_e(t.english)}</span></li>"
        for t in (RULE_TEXTS[r.source] for r in study.rules if r.source in RULE_TEXTS)
    )
    parts.append(
        "<h2>The book's weight rules</h2>"
        + _table(
            ["rule", "what it asks", "value", "limit", "unit", "met", "note"],
            wrows,
            left=(0, 1, 4, 5, 6),
        )
        + f"<ul>{explained}</ul>"
        + "<p class='note'>Line numbers of the book's OCR text (仿生机械学, source file "
        "000_f79f72c676d090fb.txt); 'info' is a rule that only informs (no pass or fail).</p>"
    )
    # per-joint plots
    parts.append("<h2>Torque and speed per joint under the motor's envelope</h2>")
    for j, name in enumerate(env.joint_names):
        parts.append(
            f"<div class='joint'><h3>{_e(name)}</h3>" + _png(joint_figure(study, j)) + "</div>"
        )
    parts.append(
        "<h2>Catalogue</h2>"
        f"<p class='note'>{_e(Path(study.catalogue.motor_source).name)}: "
        f"{_e(source_note(study.catalogue.motor_source))}</p>"
        f"<p class='note'>{_e(Path(study.catalogue.gearbox_source).name)}: "
        f"{_e(source_note(study.catalogue.gearbox_source))}</p>"
    )
    if study.timings:
        parts.append(
            "<p class='note'>run time: "
            + ", ".join(f"{k} {v:.2f} s" for k, v in study.timings.items())
            + "</p>"
        )
    parts.append("</body></html>")
    return "\n".join(parts)


def write(
    study, path, *, viewer=None, title: str | None = None, inputs: dict | None = None
) -> Path:
    """Write :func:`render` to ``path`` atomically (UTF-8); returns the path.  For the
    animation: ``viewer=anthroarm.viewer.pages.activities_html(study)``."""
    path = Path(path)
    atomic_write_text(path, render(study, viewer=viewer, title=title, inputs=inputs))
    return path
