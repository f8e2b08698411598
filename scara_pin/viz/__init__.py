"""Pictures: plots, the arm as a stick figure, inline 3-D views for notebooks, and the live meshcat viewer.

- ``robot.plot(q)`` / :func:`plot_robot`: the arm as a matplotlib stick figure (:mod:`scara_pin.viz.stick`);
- :func:`show`: the robot in 3-D in a notebook cell (:mod:`scara_pin.viz.inline`), self-contained;
- :class:`Viewer`: a live meshcat viewer driven from Python (``display(q)``, ``play(trajectory)``;
  :mod:`scara_pin.viz.meshcat`), its server on 127.0.0.1, dying with this process;
- plots of results, one signature ``plot_*(result, path=None, *, ..., units=...)``: :mod:`scara_pin.viz.plots`
  (trajectories), :mod:`scara_pin.viz.cycle` (the cycle), the workspace's and the calibration's own.

Nothing heavy is imported here: meshcat and matplotlib load inside the functions that draw.
"""

from .inline import SceneView, show
from .meshcat import Viewer
from .stick import plot_robot

__all__ = ["SceneView", "Viewer", "plot_robot", "show"]
