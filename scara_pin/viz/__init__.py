"""Pictures: the meshcat browser viewer and its offline HTML page, inline 3-D views for notebooks, and plots.

``scara_pin.viz.show(robot, q)`` shows the robot in a notebook cell (:mod:`scara_pin.viz.inline`); the plots
are in :mod:`scara_pin.viz.plots` (trajectories) and :mod:`scara_pin.viz.cycle` (the standard cycle).
Nothing heavy is imported here: meshcat and matplotlib load inside the functions that draw.
"""

from .inline import SceneView, show

__all__ = ["SceneView", "show"]
