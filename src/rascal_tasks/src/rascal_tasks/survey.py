"""Lawnmower (boustrophedon) survey poses over a station rectangle. No ROS in here."""
import math
from typing import List, Tuple


def lawnmower(center: Tuple[float, float], size: Tuple[float, float],
              step: float) -> List[Tuple[float, float]]:
    """Camera positions [x, y] that cover the rectangle in cells no larger than `step`.

    Cells are spread evenly over the rectangle (the paper's grid started at a corner and
    overshot it); columns run along x, and y alternates direction from column to column so
    the arm never travels back across the area.
    """
    nx = max(1, math.ceil(size[0] / step - 1e-9))
    ny = max(1, math.ceil(size[1] / step - 1e-9))
    x0, y0 = center[0] - size[0] / 2, center[1] - size[1] / 2
    poses = []
    for i in range(nx):
        x = x0 + (i + 0.5) * size[0] / nx
        ys = [y0 + (j + 0.5) * size[1] / ny for j in range(ny)]
        poses.extend((x, y) for y in (ys if i % 2 == 0 else reversed(ys)))
    return poses
