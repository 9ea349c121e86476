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

and after every ``set_object`` it computes smooth vertex normals for the meshes that came
without any (:class:`~anthroarm.viewer.visuals.PackedMesh`, meshcat's ``TriangularMeshGeometry``).
"""

from __future__ import annotations

import base64
import json
import os

import umsgpack

MESHCAT_DIST = os.path.join(os.path.dirname(os.path.abspath(__import__("meshcat").__file__)), "viewer", "dist")
MAIN_JS = os.path.join(MESHCAT_DIST, "main.min.js")

#: JavaScript installed right after ``new MeshCat.Viewer(...)``: the two extra commands.
JS_PATCH = r"""
(function () {
  var base = viewer.handle_command.bind(viewer);
  function split(p) { return p.split("/").filter(function (x) { return x.length > 0; }); }
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


def page_html(commands: list[bytes] | None = None, *, live: bool = False, title: str = "anthroarm viewer") -> str:
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
    return _PAGE.format(title=title, main_js=main_js, patch=JS_PATCH, replay=replay, connect=connect)


def split_path(path: str) -> tuple[str, ...]:
    return tuple(p for p in path.split("/") if p)


class _Node:
    __slots__ = ("children", "object", "transform", "properties", "color")

    def __init__(self):
        self.children: dict[str, _Node] = {}
        self.object: bytes | None = None
        self.transform: bytes | None = None
        self.properties: dict[str, bytes] = {}
        self.color: bytes | None = None


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

        walk(self.root)
        if self.animation is not None:
            out.append(self.animation)
        return out

    def static_html(self, title: str = "anthroarm viewer") -> str:
        return page_html(self.commands(), live=False, title=title)
