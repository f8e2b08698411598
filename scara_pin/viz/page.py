"""The HTML page of the browser viewer: meshcat's scene and a pendant panel.

The panel: joint sliders, the tool pose readout, a motion player, and in the live teach page, Cartesian jog
buttons and a go-to-pose form.

One page serves both uses: :func:`scara_pin.viz.meshcat.export_html` writes it to a file that renders offline
(the panel's script reads the pose from the scene graph), and :mod:`scara_pin.viz.teach` serves it with a
``teach`` section (each request answered by the server's IK and FK). The panel's script is ``pendant.js``.
"""

from __future__ import annotations

import base64
import html
import json
from pathlib import Path
from typing import Any

__all__ = ["SHARE_GEOMETRY", "render"]

SHARE_GEOMETRY = "scara_share_geometry"
"""A page command (not meshcat's): the object at ``path`` takes the geometry of the object at ``source``.

A mesh named by several visuals is embedded once in a page: the first visual's object holds its triangles,
each other visual's object a one-triangle stand-in, replaced at load by a reference to the first one's
geometry (the page's script handles the command before meshcat sees it). Never sent to meshcat's server."""

_STYLE = """
html, body { margin: 0; height: 100%; font: 13px/1.35 system-ui, sans-serif; color: #1d232b; }
body { display: flex; }
#pendant { width: 300px; flex: none; overflow-y: auto; padding: 10px 12px; box-sizing: border-box;
           background: #f4f5f7; border-right: 1px solid #c9ced6; }
#pendant h1 { font-size: 15px; margin: 0 0 8px; }
#pendant h2 { font-size: 12px; text-transform: uppercase; letter-spacing: .04em; color: #56606c; margin: 12px 0 4px; }
#scene { position: relative; flex: 1; min-width: 0; }
#meshcat-pane { width: 100%; height: 100vh; overflow: hidden; }
label.slider { display: block; margin-bottom: 6px; }
label.slider span { display: block; }
label.slider input { width: 100%; margin: 0; }
label.slider output { display: block; font: 12px ui-monospace, monospace; color: #3a4450; }
pre { font: 12px ui-monospace, monospace; margin: 0; white-space: pre-wrap; background: #fff;
      border: 1px solid #d5d9df; padding: 4px 6px; }
.jog { display: grid; grid-template-columns: 3em 1fr 1fr; gap: 3px; align-items: center; }
.jog button { padding: 3px 0; }
#goto { display: grid; grid-template-columns: auto 1fr; gap: 3px 6px; align-items: center; }
#goto input { width: 100%; box-sizing: border-box; }
#ik-status.refused { color: #b3261e; font-weight: 600; }
#ik-status.ok { color: #1e6b34; }
#player { display: flex; gap: 6px; align-items: center; }
#player input { flex: 1; }
"""

_TEACH = """
<h2>Cartesian jog (base frame)</h2>
<div class="jog">
  <span></span><span>&minus;</span><span>+</span>
  <span>x</span><button id="jog-x-">x &minus;</button><button id="jog-x+">x +</button>
  <span>y</span><button id="jog-y-">y &minus;</button><button id="jog-y+">y +</button>
  <span>z</span><button id="jog-z-">z &minus;</button><button id="jog-z+">z +</button>
  <span>yaw</span><button id="jog-yaw-">yaw &minus;</button><button id="jog-yaw+">yaw +</button>
</div>
<p><label>step <input id="jog-step" type="number" value="10" min="0" step="any" style="width:6em">
 mm / deg</label></p>
<p><label>elbow branch <select id="branch">{options}</select></label> now: <b id="branch-now">?</b></p>
<h2>Go to pose</h2>
<form id="goto">
  <label for="goto-x">x [mm]</label><input id="goto-x" name="x" type="number" step="any" required>
  <label for="goto-y">y [mm]</label><input id="goto-y" name="y" type="number" step="any" required>
  <label for="goto-z">z [mm]</label><input id="goto-z" name="z" type="number" step="any" required>
  <label for="goto-yaw">yaw [deg]</label><input id="goto-yaw" name="yaw" type="number" step="any" required>
  <span></span><button type="submit" id="goto-submit">go</button>
</form>
<h2>IK status</h2>
<pre id="ik-status">-</pre>
<h2>Joint values (server)</h2>
<pre id="joint-values">-</pre>
"""

_PLAYER = """
<h2>Motion</h2>
<div id="player"><button id="play" type="button">play</button>
<input id="time" type="range" min="0" max="1" step="any" value="0"><output id="time-value">0.000 s</output></div>
"""


def _script_json(value: Any) -> str:
    """JSON safe inside a ``<script>`` element (no ``</`` can close it early)."""
    return json.dumps(value, separators=(",", ":")).replace("</", "<\\/")


def render(title: str, viewer_js: str, commands: list[bytes], data: dict[str, Any] | None) -> str:
    """Make the page: meshcat's viewer script, the scene's commands replayed at load, and the panel.

    Args:
        title: the page title.
        viewer_js: meshcat's viewer script (``</script`` already escaped).
        commands: the scene's msgpack commands, applied in order at load (no fetch); meshcat's, and
            :data:`SHARE_GEOMETRY` (a mesh embedded once, shown by several visuals).
        data: the panel's data (:meth:`scara_pin.viz.meshcat._Scene.page_data`, plus ``q``, and ``motion``
            or ``teach``); None for a page without a panel.
    """
    share = SHARE_GEOMETRY
    encoded = ",\n".join(f'"{base64.b64encode(c).decode("ascii")}"' for c in commands)
    panel = script = ""
    if data is not None:
        section = ""
        if data.get("motion"):
            section = _PLAYER
        if data.get("teach"):
            options = "".join(
                f'<option value="{html.escape(value)}">{html.escape(label)}</option>'
                for value, label in data["teach"]["branches"]
            )
            section += _TEACH.replace("{options}", options)
        panel = f"""<div id="pendant">
<h1>{html.escape(str(data["robot"]))}</h1>
<h2>Joints</h2>
<div id="joint-sliders"></div>
<h2>tool0 in base</h2>
<pre id="tool-pose">-</pre>
{section}
</div>"""
        pendant = (Path(__file__).with_name("pendant.js")).read_text(encoding="utf-8")
        script = f"""<script type="application/json" id="scara-data">{_script_json(data)}</script>
<script>
{pendant}
</script>"""
    return f"""<!DOCTYPE html>
<html>
<head>
<meta charset="utf-8">
<title>{html.escape(title)}</title>
<style>{_STYLE}</style>
</head>
<body>
{panel}
<div id="scene"><div id="meshcat-pane"></div></div>
<script>
{viewer_js}
</script>
<script>
var viewer = new MeshCat.Viewer(document.getElementById("meshcat-pane"));
(function () {{
  // A mesh named by several visuals is embedded once: each other visual's object takes its geometry.
  var handle = viewer.handle_command.bind(viewer);
  function object(path) {{
    var names = path.split("/").filter(function (name) {{ return name.length > 0; }});
    return viewer.scene_tree.find(names.concat(["<object>"])).object;
  }}
  viewer.handle_command = function (command) {{
    if (command.type !== "{share}") return handle(command);
    var target = object(command.path), source = object(command.source);
    if (target.isMesh && source.isMesh) {{
      target.geometry.dispose();
      target.geometry = source.geometry;
      viewer.set_dirty();
    }}
  }};
}})();
(function () {{
  // The scene, as msgpack commands (base64): decoded and applied synchronously, in order; no fetch.
  var commands = [
{encoded}
  ];
  function bytes(text) {{
    var raw = atob(text), out = new Uint8Array(raw.length);
    for (var i = 0; i < raw.length; i++) out[i] = raw.charCodeAt(i);
    return out;
  }}
  for (var i = 0; i < commands.length; i++) viewer.handle_command_bytearray(bytes(commands[i]));
  window.scaraSceneCommands = commands.length;
}})();
</script>
{script}
</body>
</html>
"""
