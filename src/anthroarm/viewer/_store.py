"""The meshcat scene as data: a tree of packed commands, and the HTML page that replays it.

This module is shared by the in-process :class:`~anthroarm.viewer.Viewer` (which keeps a
mirror of the scene so that a static HTML file can be written without any server) and by the
server subprocess ``_server.py`` (which replays the scene to every browser that connects).
It imports nothing from anthroarm so that the server starts fast (it is run by file path).

Two commands are added to meshcat's protocol (handled by the page's JavaScript patch,
:data:`JS_PATCH`):

``anthroarm_batch``  ``{"type", "path": "", "commands": [cmd, ...]}`` — applied in one go, so a
                     pose update (one transform per link) reaches the browser as ONE websocket
                     message and is never drawn half-applied.
``anthroarm_color``  ``{"type", "path", "color": [r, g, b(, a)]}`` — recolour every mesh under
                     ``path`` (used for joint-limit proximity), without resending geometry.

``anthroarm_ui``     ``{"type", "path", "spec": {"kind": "legend" | "note" | "teach", ...}}`` — an
                     HTML overlay on the page (a colour legend, a line of text, the joint
                     sliders of ``Viewer.teach`` with their forward kinematics), built with
                     ``textContent`` only; deleting ``path`` or a parent removes it.

and after every ``set_object`` it computes smooth vertex normals for the meshes that came
without any (:class:`~anthroarm.viewer.meshes.PackedMesh`, meshcat's ``TriangularMeshGeometry``).
"""

from __future__ import annotations

import base64
import json
import os

import umsgpack

MESHCAT_DIST = os.path.join(
    os.path.dirname(os.path.abspath(__import__("meshcat").__file__)), "viewer", "dist"
)
MAIN_JS = os.path.join(MESHCAT_DIST, "main.min.js")

#: JavaScript installed right after ``new MeshCat.Viewer(...)``: the two extra commands.
JS_PATCH = r"""
(function () {
  var base = viewer.handle_command.bind(viewer);
  function split(p) { return p.split("/").filter(function (x) { return x.length > 0; }); }
  // ---- HTML overlays (legends, notes, teach sliders): built with textContent only
  var uiNodes = {};
  function el(tag, css, text) {
    var e = document.createElement(tag);
    if (css) { e.style.cssText = css; }
    if (text !== undefined) { e.textContent = String(text); }
    return e;
  }
  function panel(id, css) {
    var p = document.getElementById(id);
    if (!p) { p = el("div", css); p.id = id; document.body.appendChild(p); }
    return p;
  }
  var BOX = "background:rgba(255,255,255,0.88);border:1px solid #9aa5b4;border-radius:4px;padding:5px 8px;" +
            "margin-top:6px;font:12px/1.35 sans-serif;color:#1d2430;";
  function css(c) { return "rgb(" + [0, 1, 2].map(function (k) { return Math.round(255 * c[k]); }).join(",") + ")"; }
  function dropUi(path) {
    var pre = split(path).join("/");
    Object.keys(uiNodes).forEach(function (k) {
      if (k === pre || k.indexOf(pre + "/") === 0 || pre === "") { uiNodes[k].remove(); delete uiNodes[k]; }
    });
  }
  function legend(spec) {
    var box = el("div", BOX);
    box.className = "anthroarm-legend";
    box.appendChild(el("div", "font-weight:600", spec.title));
    if (spec.stops) {
      box.appendChild(el("div", "height:10px;width:180px;border:1px solid #555;margin-top:2px;background:linear-gradient(to right," +
                                spec.stops.map(css).join(",") + ")"));
      var ticks = el("div", "display:flex;justify-content:space-between;width:182px");
      (spec.ticks || []).forEach(function (t) { ticks.appendChild(el("span", "", t)); });
      box.appendChild(ticks);
    }
    (spec.entries || []).forEach(function (e) {
      var row = el("div", "display:flex;align-items:center;gap:6px");
      row.appendChild(el("span", "display:inline-block;width:22px;height:10px;border:1px solid #555;background:" + css(e[0])));
      row.appendChild(el("span", "", e[1]));
      box.appendChild(row);
    });
    return box;
  }
  // row-major 4x4 helpers for the teach panel's forward kinematics
  function mul(A, B) {
    var C = new Array(16);
    for (var i = 0; i < 4; i++) { for (var j = 0; j < 4; j++) {
      var s = 0; for (var k = 0; k < 4; k++) { s += A[4 * i + k] * B[4 * k + j]; } C[4 * i + j] = s; } }
    return C;
  }
  var EYE = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1];
  function motion(kind, a, t) {
    if (kind === "prismatic") { return [1, 0, 0, a[0] * t, 0, 1, 0, a[1] * t, 0, 0, 1, a[2] * t, 0, 0, 0, 1]; }
    var c = Math.cos(t), s = Math.sin(t), v = 1 - c, x = a[0], y = a[1], z = a[2];
    return [c + x * x * v, x * y * v - z * s, x * z * v + y * s, 0,
            y * x * v + z * s, c + y * y * v, y * z * v - x * s, 0,
            z * x * v - y * s, z * y * v + x * s, c + z * z * v, 0, 0, 0, 0, 1];
  }
  function interp(xs, ys, x) {   // piecewise linear on increasing xs, held at the ends (Coupling tables)
    var n = xs.length;
    if (x <= xs[0]) { return ys[0]; }
    if (x >= xs[n - 1]) { return ys[n - 1]; }
    var lo = 0, hi = n - 1;
    while (hi - lo > 1) { var m = (lo + hi) >> 1; if (xs[m] <= x) { lo = m; } else { hi = m; } }
    return ys[lo] + (ys[hi] - ys[lo]) * (x - xs[lo]) / (xs[hi] - xs[lo]);
  }
  function colMajor(M) { var o = []; for (var j = 0; j < 4; j++) { for (var i = 0; i < 4; i++) { o.push(M[4 * i + j]); } } return o; }
  function teach(spec) {
    var theta = spec.theta.slice();
    function pose() {
      var T = [];
      for (var j = 0; j < spec.joints.length; j++) {
        var J = spec.joints[j];
        if (J.xs) { theta[j] = interp(J.xs, J.ys, theta[J.src]); }
        else if (J.src >= 0) { theta[j] = J.mult * theta[J.src] + J.off; }
        T.push(mul(mul(J.parent >= 0 ? T[J.parent] : EYE, J.placement), motion(J.kind, J.axis, theta[j])));
      }
      var cmds = spec.movers.map(function (m) {
        var M = m.joint >= 0 ? T[m.joint] : EYE;
        return {type: "set_transform", path: m.path, matrix: colMajor(m.offset ? mul(M, m.offset) : M)};
      });
      var L = spec.limits;
      if (L) {   // joint-limit colours, as Viewer._color_commands: max proximity over the group's joints
        L.groups.forEach(function (g) {
          var p = 0;
          g.joints.forEach(function (j) {
            var lo = L.lower[j], hi = L.upper[j];
            if (lo !== null && hi !== null && hi > lo) {
              p = Math.max(p, Math.min(1, Math.abs(theta[j] - 0.5 * (lo + hi)) / (0.5 * (hi - lo))));
            }
          });
          var w = Math.min(1, Math.max(0, (p - L.warn) / (1 - L.warn)));
          cmds.push({type: "anthroarm_color", path: g.path,
                     color: [0, 1, 2].map(function (k) { return (1 - w) * g.base[k] + w * L.red[k]; })});
        });
      }
      viewer.handle_command({type: "anthroarm_batch", path: "", commands: cmds});
      var P = mul(spec.tool.joint >= 0 ? T[spec.tool.joint] : EYE, spec.tool.offset);
      var xyz = [P[3], P[7], P[11]];
      var rpy = [Math.atan2(P[9], P[10]), Math.asin(Math.max(-1, Math.min(1, -P[8]))), Math.atan2(P[4], P[0])];
      readout.textContent = spec.tool.name + ": x y z " + xyz.map(function (v) { return (1000 * v).toFixed(1); }).join(" ") +
        " mm, r p y " + rpy.map(function (v) { return (180 / Math.PI * v).toFixed(1); }).join(" ") + "°";
      window.anthroarm_teach = {theta: theta.slice(), poses: T, tool: {xyz: xyz, rpy: rpy}};
    }
    var box = el("details", BOX + "max-height:85vh;overflow-y:auto;");   // click the title to fold it away
    box.className = "anthroarm-teach";
    box.open = true;
    box.appendChild(el("summary", "font-weight:600;margin-bottom:2px;cursor:pointer", spec.title));
    var rows = box;
    spec.sliders.forEach(function (s) {
      // name (full name on hover) | a slider (about 1.2 px per degree of a 330° range) | a number box | unit
      var row = el("div", "display:grid;grid-template-columns:150px 280px 70px 22px;align-items:center;gap:4px");
      var label = el("span", "overflow:hidden;text-overflow:ellipsis;white-space:nowrap", s.name);
      label.title = s.name;
      row.appendChild(label);
      var input = el("input", "width:280px;margin:0");
      input.type = "range"; input.min = s.min; input.max = s.max; input.step = s.step; input.value = s.value;
      input.dataset.joint = s.name; input.title = s.name;
      var num = el("input", "width:66px;height:16px;padding:0 2px;font:12px sans-serif;text-align:right;font-variant-numeric:tabular-nums");
      num.type = "number"; num.min = s.min; num.max = s.max; num.step = s.step;
      num.value = Number(s.value).toFixed(s.digits);
      num.className = "anthroarm-value"; num.dataset.box = s.name; num.title = s.name + " (" + s.unit + ")";
      function set(v, from) {
        v = Math.min(parseFloat(s.max), Math.max(parseFloat(s.min), v));
        if (from !== input) { input.value = v; }
        if (from !== num) { num.value = Number(v).toFixed(s.digits); }
        theta[s.joint] = v * s.scale;
        pose();
      }
      input.addEventListener("input", function () { set(parseFloat(input.value), input); });
      num.addEventListener("change", function () {
        var v = parseFloat(num.value);
        if (isFinite(v)) { set(v, null); } else { num.value = Number(input.value).toFixed(s.digits); }
      });
      row.appendChild(input); row.appendChild(num); row.appendChild(el("span", "", s.unit));
      rows.appendChild(row);
    });
    var readout = el("div", "margin-top:3px;font-variant-numeric:tabular-nums");
    readout.className = "anthroarm-tool";
    box.appendChild(readout);
    pose();
    return box;
  }
  // the 3-D pane gives way to an open teach panel, so the panel never hides the robot
  function fitPane() {
    var pane = document.getElementById("meshcat-pane");
    var open = document.querySelector("#anthroarm-teach details[open]");
    var w = open ? open.parentNode.offsetWidth + 16 : 0;
    pane.style.marginLeft = w + "px";
    pane.style.width = w ? "calc(100vw - " + w + "px)" : "100vw";
    viewer.set_3d_pane_size();
  }
  function ui(path, spec) {
    var key = split(path).join("/");
    if (uiNodes[key]) { uiNodes[key].remove(); delete uiNodes[key]; }
    var node = null;
    if (spec.kind === "legend") { node = legend(spec); }
    else if (spec.kind === "note") { node = el("div", BOX, spec.text); node.className = "anthroarm-note"; }
    else if (spec.kind === "teach") { node = teach(spec); }
    if (node === null) { return; }
    var where = spec.kind === "teach" ? panel("anthroarm-teach", "position:absolute;left:8px;top:2px;z-index:10")
                                      : panel("anthroarm-legends", "position:absolute;left:8px;bottom:8px;z-index:10");
    where.appendChild(node);
    uiNodes[key] = node;
    if (spec.kind === "teach") { node.addEventListener("toggle", fitPane); fitPane(); }
  }
  viewer.handle_command = function (cmd) {
    if (cmd.type === "anthroarm_batch") {
      for (var i = 0; i < cmd.commands.length; i++) { viewer.handle_command(cmd.commands[i]); }
      return;
    }
    if (cmd.type === "anthroarm_color") {
      var node = viewer.scene_tree.find(split(cmd.path));
      var c = cmd.color;
      node.object.traverse(function (o) {
        if (o.material && o.material.color) {
          o.material.color.setRGB(c[0], c[1], c[2]);
          if (c.length > 3) { o.material.opacity = c[3]; o.material.transparent = c[3] < 1.0; }
        }
      });
      viewer.set_dirty();
      return;
    }
    if (cmd.type === "anthroarm_ui") { ui(cmd.path, cmd.spec); return; }
    if (cmd.type === "delete") { dropUi(cmd.path); fitPane(); }
    base(cmd);
    if (cmd.type === "set_object") {   // meshes sent without normals (PackedMesh): smooth normals here
      var made = viewer.scene_tree.find(split(cmd.path));
      made.object.traverse(function (o) {
        var g = o.isMesh && o.geometry;
        if (g && g.getAttribute && g.getAttribute("position") && !g.getAttribute("normal")) { g.computeVertexNormals(); }
      });
    }
  };
  window.anthroarm_ready = true;
})();
"""

_PAGE = """<!DOCTYPE html>
<html>
<head><meta charset="utf-8"><title>{title}</title>
<style>body {{ margin: 0; background: linear-gradient(#fbfcfe, #c9d3e0); }} #meshcat-pane {{ width: 100vw; height: 100vh; overflow: hidden; }}</style>
</head>
<body>
<div id="meshcat-pane"></div>
{main_js}
<script>
var viewer = new MeshCat.Viewer(document.getElementById("meshcat-pane"));
{patch}
{replay}
{connect}
</script>
</body>
</html>
"""

_REPLAY = """(function () {{
  var cmds = {cmds};
  for (var i = 0; i < cmds.length; i++) {{
    var s = atob(cmds[i]); var b = new Uint8Array(s.length);
    for (var j = 0; j < s.length; j++) {{ b[j] = s.charCodeAt(j); }}
    viewer.handle_command_bytearray(b);
  }}
  window.anthroarm_commands = cmds.length;
}})();"""


def page_html(
    commands: list[bytes] | None = None, *, live: bool = False, title: str = "anthroarm viewer"
) -> str:
    """The viewer page.

    ``live=True``: the page served by the server (loads ``main.min.js`` from the server and
    connects to its websocket).  ``live=False``: a self-contained static file with meshcat's
    JavaScript inlined and ``commands`` (packed msgpack) replayed synchronously on load.
    """
    if live:
        main_js = '<script type="text/javascript" src="main.min.js"></script>'
        connect = 'try { viewer.connect(); } catch (e) { console.info("not connected", e); }'
    else:
        with open(MAIN_JS, encoding="utf-8") as f:
            src = f.read()
        main_js = "<script>\n" + src.replace("</script>", "<\\/script>") + "\n</script>"
        connect = ""
    replay = ""
    if commands:
        enc = [base64.b64encode(c).decode("ascii") for c in commands]
        replay = _REPLAY.format(cmds=json.dumps(enc))
    return _PAGE.format(
        title=title, main_js=main_js, patch=JS_PATCH, replay=replay, connect=connect
    )


def split_path(path: str) -> tuple[str, ...]:
    return tuple(p for p in path.split("/") if p)


class _Node:
    __slots__ = ("children", "object", "transform", "properties", "color", "ui")

    def __init__(self):
        self.children: dict[str, _Node] = {}
        self.object: bytes | None = None
        self.transform: bytes | None = None
        self.properties: dict[str, bytes] = {}
        self.color: bytes | None = None
        self.ui: bytes | None = None


class SceneStore:
    """The current scene as packed meshcat commands, one slot per (node, kind).

    Repeated transforms or properties of the same node overwrite each other, so the replay
    (``commands()``) is as long as the scene, not as long as its history.
    """

    def __init__(self):
        self.root = _Node()
        self.animation: bytes | None = None

    def _find(self, parts) -> _Node:
        node = self.root
        for p in parts:
            node = node.children.setdefault(p, _Node())
        return node

    def apply(self, cmd: dict, packed: bytes | None = None) -> None:
        """Record one lowered command (the dict meshcat's ``lower()`` returns)."""
        kind = cmd["type"]
        if kind == "anthroarm_batch":
            for c in cmd["commands"]:
                self.apply(c)
            return
        if packed is None:
            packed = umsgpack.packb(cmd)
        parts = split_path(cmd.get("path", ""))
        if kind == "set_object":
            node = self._find(parts)
            node.object = packed
            node.properties = {}
            node.color = None
        elif kind == "set_transform":
            self._find(parts).transform = packed
        elif kind == "set_property":
            self._find(parts).properties[cmd["property"]] = packed
        elif kind == "anthroarm_color":
            self._find(parts).color = packed
        elif kind == "anthroarm_ui":
            self._find(parts).ui = packed
        elif kind == "set_animation":
            self.animation = packed if cmd.get("animations") else None
        elif kind == "delete":
            if not parts:
                self.root = _Node()
                self.animation = None
                return
            parent = self._find(parts[:-1])
            parent.children.pop(parts[-1], None)
        # other commands (capture_image, ...) are not part of the scene

    def commands(self) -> list[bytes]:
        """Packed commands that rebuild the scene, parents before children, animation last."""
        out: list[bytes] = []

        def walk(node: _Node):
            if node.object is not None:
                out.append(node.object)
            out.extend(node.properties.values())
            if node.transform is not None:
                out.append(node.transform)
            for child in node.children.values():
                walk(child)
            if node.color is not None:  # after the children: colours every mesh below
                out.append(node.color)
            if node.ui is not None:
                out.append(node.ui)

        walk(self.root)
        if self.animation is not None:
            out.append(self.animation)
        return out

    def static_html(self, title: str = "anthroarm viewer") -> str:
        return page_html(self.commands(), live=False, title=title)
