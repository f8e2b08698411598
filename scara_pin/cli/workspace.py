"""The ``workspace`` command."""

from __future__ import annotations

import argparse
import json
import math
from typing import TYPE_CHECKING, Any

from ..errors import InvalidInputError
from ..units import decimals_for, format_number, format_vector
from ._numbers import number
from ._options import add_cell_options, add_robot_options, add_units
from ._outputs import check_command_outputs
from ._robot import cell_from_args, robot_from_args
from ._units import Units

_TABLE_RESOLUTION = 1e-6
"""The arc table of ``workspace`` prints centres and radii to 1 um (a summary; --json gives every bit)."""

if TYPE_CHECKING:

    from ..robots import Robot


LISTED_ARC_MIN = 1e-6
"""[m] boundary arcs shorter than this (a limit just past another, by microradians: a 3.14 in an rpy) are not
listed in the text (their angles would print as one number); --json keeps every arc, the loops close."""


def cmd_workspace(args: argparse.Namespace) -> int:
    """The exact reachable region (arcs, area, radii), a ray query to its edge, and a picture."""
    from ..workspace.scara import plot_workspace, workspace

    units = Units.from_args(args)
    L = units.length
    check_command_outputs(args, {"--plot": args.plot}, figures=("--plot",))  # before any work
    robot = robot_from_args(args, units)
    cell = cell_from_args(args, units)
    if cell is not None or args.height is not None:
        return _free_workspace(args, robot, units, cell)
    if robot.kind == "palletizer":
        return _palletizer_workspace(args, robot, units)
    ws = workspace(robot)
    hit = None
    if args.ray:
        start = [units.value(n, t, "length") for n, t in zip(("x", "y"), args.ray[:2])]
        direction = [number(n, t) for n, t in zip(("dx", "dy"), args.ray[2:])]
        if (args.z is None) != (args.dz is None):
            raise InvalidInputError("--z and --dz go together (a 3-D ray also meets the vertical stroke)")
        if args.z is not None:
            start.append(units.value("--z", args.z, "length"))
            direction.append(number("--dz", args.dz))
        hit = ws.ray(start, direction)
    elif args.z is not None or args.dz is not None:
        raise InvalidInputError("--z/--dz go with --ray")
    if args.plot:
        ray = None if hit is None else (start[:2], direction[:2])
        plot_workspace(ws, args.plot, ray=ray, units=units.display, robot_name=robot.name)
    if args.json and hit is not None:
        return _print_json(args, robot, ray={"start": start, "direction": direction, **hit.to_dict()})
    if args.json:
        return _print_json(args, robot, workspace=ws.to_dict())
    n = units.length_name
    if hit is not None:
        print(f"robot     {robot.name}: ray from {units.fmt(start, 'length')} [{n}] along "
              f"{format_vector(direction, 9)}")
        print(f"edge      {units.fmt(hit.point, 'length')} [{n}]")
        print(f"distance  {units.num(hit.distance, 'length')} {n}")
        print(f"stopped by {hit.description} [{hit.limit.value}]")
    else:
        z0, z1 = ws.z_range
        print(f"robot     {robot.name}: reachable region of the wrist axis (= tool point without tool offset)")
        print(f"area      {units.num(ws.area, 'area')} {n}^2")
        print(f"radius    {units.num(ws.r_min, 'length')} .. {units.num(ws.r_max, 'length')} {n} (from the J1 axis)")
        quill = ws.geometry.names[ws.geometry.prismatic]
        print(f"z         {units.num(z0, 'length')} .. {units.num(z1, 'length')} {n} ({quill}'s stroke)")
        if ws.note is not None:
            print(f"note      {ws.note}")
        # the arc table to 1 um and 0.001 deg (--json gives every bit)
        d = decimals_for(L, _TABLE_RESOLUTION)
        print(f"boundary  {len(ws.loops)} loop(s) of {len(ws.arcs)} arcs (centre, radius [{n}], start..end angle "
              "[deg], limit):")  # fmt: skip
        short = [i for i, arc in enumerate(ws.arcs) if arc.radius * abs(arc.sweep) < LISTED_ARC_MIN]
        for i, arc in enumerate(ws.arcs):
            if i in short:
                continue
            cx, cy, r = (format_number(v * L, d) for v in (*arc.center, arc.radius))
            a0, a1 = (format_number(math.degrees(v), 3) for v in (arc.start, arc.end))
            print(f"  {i:>2}  ({cx:>11}, {cy:>11})  r {r:>11}  {a0:>8} .. {a1:<8}  {arc.description}")
        if short:
            print(f"  ({len(short)} arc(s) shorter than {LISTED_ARC_MIN * 1e6:g} um not listed: "
                  f"{', '.join(map(str, short))}; real corners of the region, kept in --json)")  # fmt: skip
    if args.plot:
        print(f"wrote     {args.plot}")
    return 0


def _print_json(args: argparse.Namespace, robot: Robot, **fields: Any) -> int:
    """``--json``: one object, the robot, the units (SI), ``fields`` and the picture written (``--plot``)."""
    out: dict[str, Any] = {"robot": robot.name, "units": {"length": "m", "angle": "rad"}, **fields}
    if args.plot:
        out["plot"] = args.plot
    print(json.dumps(out))
    return 0


def _free_workspace(args: argparse.Namespace, robot: Robot, units: Units, cell: Any) -> int:
    """``workspace --cell FILE --height Z``: the plan-view region reachable without collision at that height."""
    from ..workspace.free import free_region, plot_free_region

    if cell is None or args.height is None:
        raise InvalidInputError("--cell and --height go together: the region reachable without collision at height "
                                "Z in the cell")  # fmt: skip
    if args.ray or args.z is not None or args.dz is not None:
        raise InvalidInputError("--ray/--z/--dz do not go with --cell (the ray meets the joint limits' edge only)")
    z = units.value("--height", args.height, "length")
    h = None if args.resolution is None else units.value("--resolution", args.resolution, "length")
    yaw = None if args.yaw is None else units.value("--yaw", args.yaw, "angle")
    region = free_region(robot, cell, z, resolution=h, yaw=yaw)
    if args.plot:
        plot_free_region(region, args.plot, units=units.display, robot_name=robot.name)
    if args.json:
        return _print_json(args, robot, **region.to_dict())
    n = units.length_name
    h = region.resolution
    print(f"robot     {robot.name}: reachable without collision at z = {units.num(z, 'length')} {n} in {cell.origin}")
    print(f"free      {units.num(region.area, 'area')} {n}^2 of {units.num(region.workspace.area, 'area')} {n}^2 (the "
          f"joint limits' exact area; {units.num(region.reachable_area, 'area')} {n}^2 on this grid)")  # fmt: skip
    print(f"grid      {len(region.x)} x {len(region.y)} points {units.num(h, 'length')} {n} apart (area error at most "
          f"sqrt(2) h per unit of boundary length)")  # fmt: skip
    print(f"yaw       {region.yaw_text}")
    print(f"margin    {cell.margin * 1e3:g} mm; {len(cell.obstacles)} obstacle(s)"
          + ("" if cell.carried is None else f", carrying a {cell.carried.kind}"))  # fmt: skip
    if args.plot:
        print(f"wrote     {args.plot}")
    return 0


def _palletizer_workspace(args: argparse.Namespace, robot: Robot, units: Units) -> int:
    """The palletizer's reach envelope of tool0 in its arm plane (r from the waist axis, z)."""
    from ..workspace.palletizer import arm_plane_envelope, plot_envelope

    if args.ray or args.z is not None or args.dz is not None:
        raise InvalidInputError("--ray/--z/--dz are SCARA-only for now; a palletizer gets its arm-plane envelope")
    env = arm_plane_envelope(robot.kinematics.geometry)
    if args.plot:
        plot_envelope(env, args.plot, units=units.display, robot_name=robot.name, tool_frame=robot.tool_frame)
    if args.json:
        return _print_json(args, robot, envelope=env.to_dict())
    name = units.length_name
    print(f"robot     {robot.name}: reach envelope of {robot.tool_frame} in the arm plane (r from the waist axis, z)")
    print(f"area      {units.num(env.area, 'area')} {name}^2")
    print(f"r range   {units.fmt(env.r_range, 'length')} {name}")
    print(f"z range   {units.fmt(env.z_range, 'length')} {name}")
    print(f"arcs      {len(env.arcs)} (centre, radius [{name}], phi from the vertical [rad])")
    for a in env.arcs:
        print(f"  {a.limit:<13} centre {units.fmt(a.center, 'length')} radius {units.num(a.radius, 'length')} "
              f"phi {format_vector([a.start, a.start + a.sweep], 9)}")  # fmt: skip
    if args.plot:
        print(f"wrote     {args.plot}")
    return 0


def register(sub: Any) -> None:
    """Add the commands of this module to the ``scara-pin`` subparsers."""
    p = sub.add_parser("workspace", help="exact reachable region (arcs, area, radii); --ray: the edge along a ray")
    p.add_argument("--ray", nargs=4, metavar=("X", "Y", "DX", "DY"), help="start inside the region and plan direction")
    p.add_argument("--z", metavar="Z", help="with --ray: start height (a 3-D ray also meets the vertical stroke)")
    p.add_argument("--dz", metavar="DZ", help="with --ray: vertical direction component")
    p.add_argument("--plot", metavar="PNG", help="picture of the region (arcs coloured by limit; the ray)")
    g = p.add_argument_group("collision-free region (with --cell)")
    g.add_argument("--height", metavar="Z", help="with --cell: the tool's height [m, or mm with --mm]: the plan-view "
                   "region reachable there with every link clear of the cell by its margin (a raster)")  # fmt: skip
    g.add_argument("--resolution", metavar="H", help="the raster's spacing [m, or mm with --mm] (default: the "
                   "workspace's width / 200)")  # fmt: skip
    g.add_argument("--yaw", metavar="A", help="one tool yaw for every point [rad, or deg with --deg] (default: free "
                   "with a carried part, the first of 12 that clears; else 0)")  # fmt: skip
    add_units(p)
    add_robot_options(p)
    add_cell_options(p)
    p.set_defaults(func=cmd_workspace)
