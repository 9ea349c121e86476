"""A self-contained HTML report of a sizing :class:`~.study.Study`.

One file, no network: the person's model (segments, masses, joint ranges), the activities
animated in the meshcat viewer (:meth:`anthroarm.viewer.Viewer.static_html`, embedded once as an
``<iframe srcdoc>``: all usable activities play one after the other in one animation, so
meshcat's JavaScript (~1 MB) is in the file once), per joint the torque–time curves and the
(speed, torque) points of every activity over the chosen motor's torque–speed line and
continuous-torque limit (PNG, base64), the envelope, the chosen motors and gearboxes, the drive
mass, the book's weight rules and what did not fit.  Written atomically
(:func:`anthroarm._io.atomic_write_text`).
"""

from __future__ import annotations

import base64
import html
import io
from pathlib import Path

import numpy as np

from .._io import atomic_write_text
from .catalogue import source_note
from .envelope import CUP_HEIGHT, CUP_RADIUS

_CSS = """
body { font-family: system-ui, sans-serif; margin: 1.5em auto; max-width: 1100px; color: #222; }
h1 { font-size: 1.5em; } h2 { font-size: 1.2em; margin-top: 1.6em; border-bottom: 1px solid #ccc; }
table { border-collapse: collapse; margin: 0.6em 0; font-size: 0.9em; }
th, td { border: 1px solid #ccc; padding: 3px 8px; text-align: right; }
th { background: #f0f2f5; } td.l, th.l { text-align: left; }
.ok { color: #1a7f37; } .bad { color: #c62828; font-weight: bold; } .info { color: #555; }
.note { color: #555; font-size: 0.85em; } img { max-width: 100%; }
iframe { width: 100%; height: 480px; border: 1px solid #ccc; }
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


def _png(fig, dpi: int = 80) -> str:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi, bbox_inches="tight")
    return (
        '<img alt="plot" src="data:image/png;base64,'
        + base64.b64encode(buf.getvalue()).decode("ascii")
        + '">'
    )


def joint_figure(study, j: int):
    """The figure of joint ``j``: τ(t) of every usable activity, and its (|q̇|, |τ|) points over
    the chosen (or closest) motor + gearbox's torque–speed line at the nominal voltage
    (Eq. (9-1) through the gearbox, :meth:`anthroarm.control.motor.DCMotor.joint_torque`) and its
    continuous torque η i τ_cont.  Returns a :class:`matplotlib.figure.Figure` (no pyplot state)."""
    from matplotlib.figure import Figure

    env, js = study.envelope, study.sizing.joints[j]
    name = env.joint_names[j]
    fig = Figure(figsize=(12, 3.4))
    a0, a1 = fig.subplots(1, 2, gridspec_kw=dict(wspace=0.6))
    scale = 1.0 + study.sizing.margin
    wmax = 0.0
    for act in env.activities:
        a0.plot(act.t - act.t[0], act.tau[:, j], lw=1.2, label=act.name)
        a1.plot(np.abs(act.qd[:, j]), np.abs(act.tau[:, j]), ".", ms=2.5)
        wmax = max(wmax, float(np.max(np.abs(act.qd[:, j]))))
    a0.set_xlabel("t [s]")
    a0.set_ylabel(f"{name} torque [N m]")
    a0.axhline(0, color="k", lw=0.5)
    a0.legend(fontsize=6, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    cand = js.choice or js.closest
    if cand is not None:
        dc = cand.dc_motor()
        w0 = float(dc.no_load_speed())
        w = np.linspace(0.0, w0, 100)
        a1.plot(
            w, dc.joint_torque(w), "k-", lw=1.5, label=f"torque-speed line at {dc.V_nom:g} V (9-1)"
        )
        a1.axhline(
            dc.continuous_torque, color="tab:red", ls="--", lw=1, label="motor continuous torque"
        )
        a1.axhline(
            cand.gearbox.tau_max, color="tab:purple", ls=":", lw=1, label="gearbox intermittent"
        )
        a1.set_xlim(0, max(min(w0, 3.0 * wmax * scale), wmax * scale, 1e-3) * 1.05)
        a1.set_ylim(
            0, max(cand.gearbox.tau_max, env.peak_torque[j] * scale, dc.continuous_torque) * 1.15
        )
        a1.set_title(("" if js.choice else "closest, does not fit: ") + cand.name, fontsize=8)
    a1.set_xlabel(f"|{name} speed| [rad/s]")
    a1.set_ylabel("|torque| [N m]")
    a1.legend(fontsize=6, loc="upper right")
    return fig


def _viewer_html(study, max_frames: int = 600) -> str:
    from ..viewer import Viewer

    acts = [a for a in study.envelope.activities if len(a.q) >= 2]
    if not acts:
        return '<p class="note">no usable activity to animate</p>'
    total = sum(len(a.q) for a in acts)
    step = max(1, int(np.ceil(total / max_frames)))
    Q = np.concatenate([a.q[::step] for a in acts])
    dt = float(np.median(np.concatenate([np.diff(a.t) for a in acts]))) * step
    v = Viewer(study.robot)
    v.play(Q, dt=dt, loop=True, trace=True)
    page = v.static_html(title=f"anthroarm — {study.robot.name} activities")
    starts, t = [], 0.0
    for a in acts:
        starts.append(f"{_e(a.name)} at {t:.1f} s")
        t += len(a.q[::step]) * dt
    return (
        f'<iframe srcdoc="{_e(page)}" loading="lazy"></iframe>'
        f'<p class="note">One animation, {len(acts)} activities in turn (loops): {"; ".join(starts)}. '
        "Drag to rotate, scroll to zoom.</p>"
    )


def _person_section(study) -> str:
    robot = study.robot
    chain = robot.chain
    p = study.person
    rows = []
    for j in chain.joints:
        rows.append(
            (
                j.name,
                j.kind,
                np.array2string(np.round(j.axis, 3), separator=", "),
                f"{j.mass:.3f}",
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
    total = sum(j.mass for j in chain.joints)
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
                "its link's mass [kg]",
                "offset from parent [m]",
                "lower [deg]",
                "upper [deg]",
            ],
            rows,
            left=(0, 1, 2),
        )
    )


def _fmt_ok(ok):
    if ok is None:
        return ("info", "info")
    return ("yes", "ok") if ok else ("NO", "bad")


def render(study, *, viewer: bool = True, title: str | None = None) -> str:
    """The report's HTML text (see the module docstring); ``viewer=False`` leaves out the
    animation (and meshcat's JavaScript)."""
    env, sz = study.envelope, study.sizing
    parts = [
        f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{_e(title or 'anthroarm prosthesis sizing')}"
        f"</title><style>{_CSS}</style></head><body>",
        f"<h1>{_e(title or 'From a person to a prosthesis: joint demands and motors')}</h1>",
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
        parts.append(_viewer_html(study))
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
    # weight rules
    wrows = [
        (r.rule, r.source, f"{r.value:.2f}", f"{r.limit:.2f}", r.unit, _fmt_ok(r.ok), r.note)
        for r in study.rules
    ]
    parts.append(
        "<h2>The book's weight rules</h2>"
        + _table(
            ["rule", "book", "value", "limit", "unit", "met", "note"], wrows, left=(0, 1, 4, 5, 6)
        )
    )
    # what did not fit
    misfits = [
        f"<li>joint {_e(js.joint)}: {_e(js.reason)}</li>" for js in sz.joints if js.status != "ok"
    ]
    misfits += [
        f"<li>activity {_e(a.name)}: {_e(a.status)}: {_e(a.reason)}</li>"
        for a in study.activities
        if a.status != "ok"
    ]
    misfits += [
        f"<li>rule {_e(r.source)}: {_e(r.rule)} ({r.value:.2f} vs {r.limit:.2f} {_e(r.unit)})</li>"
        for r in study.rules
        if r.ok is False
    ]
    parts.append(
        "<h2>What did not fit</h2>"
        + (f"<ul>{''.join(misfits)}</ul>" if misfits else "<p>everything fits</p>")
    )
    # per-joint plots
    parts.append("<h2>Torque and speed per joint over the motor's envelope</h2>")
    for j, name in enumerate(env.joint_names):
        parts.append(f"<h3>{_e(name)}</h3>" + _png(joint_figure(study, j)))
    parts.append(
        "<h2>Catalogue</h2>"
        f"<p class='note'>{_e(study.catalogue.motor_source)}: {_e(source_note(study.catalogue.motor_source))}</p>"
        f"<p class='note'>{_e(study.catalogue.gearbox_source)}: "
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


def write(study, path, *, viewer: bool = True, title: str | None = None) -> Path:
    """Write :func:`render` to ``path`` atomically (UTF-8); returns the path."""
    path = Path(path)
    atomic_write_text(path, render(study, viewer=viewer, title=title))
    return path
