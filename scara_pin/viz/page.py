"""The HTML page of the browser viewer: meshcat's scene and a pendant panel.

The panel: a units switch (mm/deg or m/rad), the tool pose readout (named by the real tool and base frames),
joint sliders, a motion player, and in the live teach page a status line that stays at the top, joint and
Cartesian (base or tool frame) jog buttons by step or held, a speed override, the taught points and a
go-to-pose form. meshcat's own control panel is hidden unless the address asks for it (``?controls=1``) or
the panel's checkbox shows it.

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
#pendant { width: 320px; flex: none; overflow-y: auto; padding: 0 12px 10px; box-sizing: border-box;
           background: #f4f5f7; border-right: 1px solid #c9ced6; height: 100vh; }
#pendant h1 { font-size: 15px; margin: 0 0 4px; }
#pendant h2 { font-size: 12px; letter-spacing: .04em; color: #56606c; margin: 10px 0 4px; }
#top { position: sticky; top: 0; z-index: 2; background: #f4f5f7; padding: 8px 0 6px;
       border-bottom: 1px solid #d5d9df; }
#scene { position: relative; flex: 1; min-width: 0; }
#meshcat-pane { width: 100%; height: 100vh; overflow: hidden; }
label.slider { display: block; margin-bottom: 6px; }
label.slider span { display: block; }
label.slider input { width: 100%; margin: 0; }
label.slider output { display: block; font: 12px ui-monospace, monospace; color: #3a4450; }
pre { font: 12px ui-monospace, monospace; margin: 0; white-space: pre-wrap; background: #fff;
      border: 1px solid #d5d9df; padding: 4px 6px; }
.units, .modes { display: flex; gap: 10px; flex-wrap: wrap; align-items: center; margin: 2px 0; }
#ik-status { font: 12px ui-monospace, monospace; white-space: pre-wrap; margin: 4px 0 0; padding: 3px 6px;
             border-radius: 3px; background: #fff; border: 1px solid #d5d9df; max-height: 6.5em; overflow-y: auto; }
#ik-status.refused { color: #b3261e; border-color: #b3261e; font-weight: 600; }
#ik-status.stopped { color: #8a5300; border-color: #c98a00; font-weight: 600; }
#ik-status.ok { color: #1e6b34; }
.jog { display: grid; grid-template-columns: 3.2em 1fr 1fr; gap: 3px; align-items: center; }
.jog button { padding: 4px 0; touch-action: none; user-select: none; }
.jog button.held { background: #ffd18a; }
.steps { display: grid; grid-template-columns: auto 1fr auto; gap: 3px 6px; align-items: center; margin: 4px 0; }
.steps input { width: 100%; box-sizing: border-box; }
input[aria-invalid=true] { outline: 2px solid #b3261e; }
#goto { display: grid; grid-template-columns: auto 1fr; gap: 3px 6px; align-items: center; }
#goto input { width: 100%; box-sizing: border-box; }
#points { width: 100%; border-collapse: collapse; font-size: 12px; }
#points td { padding: 1px 2px; vertical-align: middle; }
#points td.pose { font: 11px ui-monospace, monospace; color: #3a4450; }
#points tr.recorded td { background: #d9f2df; }
#points input { width: 5.5em; }
.row { display: flex; gap: 4px; flex-wrap: wrap; align-items: center; margin: 4px 0; }
#player { display: flex; gap: 6px; align-items: center; }
#player input { flex: 1; }
"""

_UNITS = """
<div class="units" role="radiogroup" aria-label="units">units:
<label><input type="radio" name="units" value="mm" checked> mm, deg</label>
<label><input type="radio" name="units" value="m"> m, rad</label></div>
"""

_STATUS = """<pre id="ik-status" role="status" aria-live="polite">-</pre>"""

_TEACH = """
<h2>Jog</h2>
<div class="modes" role="radiogroup" aria-label="jog frame">
<label><input type="radio" name="frame" value="joint"> joint</label>
<label><input type="radio" name="frame" value="base" checked> base</label>
<label><input type="radio" name="frame" value="tool"> tool</label></div>
<div class="modes" role="radiogroup" aria-label="jog mode">
<label><input type="radio" name="jogmode" value="step" checked> step</label>
<label><input type="radio" name="jogmode" value="hold"> hold (continuous)</label></div>
<div class="steps">
  <label for="jog-step">step, lengths</label><input id="jog-step" type="number" value="10" min="0" step="any">
  <span class="u-len">mm</span>
  <label for="jog-step-angle">step, angles</label><input id="jog-step-angle" type="number" value="5" min="0" step="any">
  <span class="u-ang">deg</span>
  <label for="speed">speed (hold)</label><input id="speed" type="range" min="1" max="100" step="1" value="25">
  <output id="speed-value">25 %</output>
</div>
<div class="jog" id="jog-grid">{rows}</div>
{cell}<p class="row">branch now: <b id="branch-now">?</b></p>
<h2>Points</h2>
<div class="row"><input id="point-name" placeholder="name (P1...)" size="10">
<select id="point-form" title="record the joint values, or the pose with its branch and wrist turn">
<option value="joint">joint</option><option value="pose">pose</option></select>
<button type="button" id="record">record</button></div>
<table id="points"><tbody></tbody></table>
<div class="row"><button type="button" id="points-save" {save}>save</button>
<button type="button" id="points-load" {save}>reload</button>
<a id="points-yaml" href="api/points/export?format=yaml" download="points.yaml">YAML</a>
<a id="points-csv" href="api/points/export?format=csv" download="points.csv">CSV</a></div>
<p class="row" id="points-file">{file}</p>
<h2>Go to pose</h2>
<form id="goto">
  <label for="goto-x">x [<span class="u-len">mm</span>]</label>
  <input id="goto-x" name="x" type="number" step="any" required>
  <label for="goto-y">y [<span class="u-len">mm</span>]</label>
  <input id="goto-y" name="y" type="number" step="any" required>
  <label for="goto-z">z [<span class="u-len">mm</span>]</label>
  <input id="goto-z" name="z" type="number" step="any" required>
  <label for="goto-yaw">yaw [<span class="u-ang">deg</span>]</label>
  <input id="goto-yaw" name="yaw" type="number" step="any" required>
  <label for="branch">branch</label><select id="branch">{options}</select>
  <span></span><button type="submit" id="goto-submit">go</button>
</form>
<h2>Joint values (server)</h2>
<pre id="joint-values">-</pre>
"""

_ROW = """<span id="jog-label-{i}">{label}</span><button type="button" id="jog-{i}-" data-row="{i}" data-sign="-1">
{label} &minus;</button><button type="button" id="jog-{i}+" data-row="{i}" data-sign="1">{label} +</button>"""

_CONTROLS = """
<p class="row"><label><input type="checkbox" id="show-controls"> meshcat's controls</label></p>
"""

_PLAYER = """
<h2>Motion</h2>
<div id="player"><button id="play" type="button">play</button>
<input id="time" type="range" min="0" max="1" step="any" value="0"><output id="time-value">0.000 s</output></div>
"""


def _script_json(value: Any) -> str:
    """JSON safe inside a ``<script>`` element (no ``</`` can close it early)."""
    return json.dumps(value, separators=(",", ":")).replace("</", "<\\/")


def _panel(data: dict[str, Any]) -> str:
    """The pendant panel: the sticky top (robot, status line, units), readouts, and the player or the teach part."""
    teach = data.get("teach")
    section = _PLAYER if data.get("motion") else ""
    if teach:
        options = "".join(f'<option value="{html.escape(value)}">{html.escape(label)}</option>'
                          for value, label in teach["branches"])  # fmt: skip
        rows = "".join(_ROW.format(i=i, label=label) for i, label in enumerate(("x", "y", "z", "rz")))
        path = teach.get("points_file", "")
        file = (f"file: <code>{html.escape(path)}</code>" if path
                else "no points file: start with <code>--points FILE</code> to save; download meanwhile")  # fmt: skip
        cell = teach.get("cell")  # its words: each length "<number> m", restated in the page's units by the script
        cell_row = (f'<p class="row" id="cell-info" data-text="{html.escape(cell, quote=True)}">'
                    f"{html.escape(cell)}</p>\n" if cell else "")  # fmt: skip
        section += (_TEACH.replace("{options}", options).replace("{rows}", rows).replace("{cell}", cell_row)
                    .replace("{save}", "" if path else "disabled").replace("{file}", file))  # fmt: skip
    frames = f"{html.escape(str(data.get('tool_frame', 'tool')))} in {html.escape(str(data.get('base_frame', 'base')))}"
    return f"""<div id="pendant">
<div id="top">
<h1>{html.escape(str(data["robot"]))}</h1>
{_STATUS if teach else ""}
{_UNITS}
</div>
<h2 id="pose-title">{frames}</h2>
<pre id="tool-pose">-</pre>
{section}
<h2>Joints</h2>
<div id="joint-sliders"></div>
{_CONTROLS}
</div>"""


def render(title: str, viewer_js: str, commands: list[bytes], data: dict[str, Any] | None) -> str:
    """Make the page: meshcat's viewer script, the scene's commands replayed at load, and the panel.

    Args:
        title: the page title.
        viewer_js: meshcat's viewer script (``</script`` already escaped).
        commands: the scene's msgpack commands, applied in order at load (no fetch); meshcat's, and
            :data:`SHARE_GEOMETRY` (a mesh embedded once, shown by several visuals).
        data: the panel's data (the scene's joints, tool and limits, plus ``q``, and ``motion``
            or ``teach``); None for a page without a panel.
    """
    encoded = ",\n".join(f'"{base64.b64encode(c).decode("ascii")}"' for c in commands)
    panel = script = ""
    if data is not None:
        panel = _panel(data)
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
// meshcat's own control panel ("Open Controls") is hidden unless asked for: ?controls=1 in the address
viewer.gui.domElement.style.display = /[?&]controls=1(&|$)/.test(location.search) ? "" : "none";
(function () {{
  // A mesh named by several visuals is embedded once: each other visual's object takes its geometry.
  var handle = viewer.handle_command.bind(viewer);
  function object(path) {{
    var names = path.split("/").filter(function (name) {{ return name.length > 0; }});
    return viewer.scene_tree.find(names.concat(["<object>"])).object;
  }}
  viewer.handle_command = function (command) {{
    if (command.type !== "{SHARE_GEOMETRY}") return handle(command);
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
