"""Which sherd is picked next: the one selection policy, over the merged survey of the pickup
area (`perception.selection_policy`). No ROS in here.
"""

import math
from typing import List

from rascal_tasks.rig import Observation


def in_pick_order(found: List[Observation], policy: str) -> List[Observation]:
    """`found` in the order to pick it by `policy`:
    - nearest: nearest the arm's base first (the shortest reach, the least time; the default);
    - largest: largest length x width first;
    - most_isolated: largest edge-to-edge gap to its nearest neighbour first.
    Python's sort is stable: detection order breaks ties."""
    if policy == "largest":
        return sorted(found, key=lambda o: -o.length * o.width)
    if policy == "most_isolated":

        def gap(o):  # to the nearest neighbour, edge to edge along the line of centres
            return min(
                (o.distance_to(p.x, p.y) - (o.length + p.length) / 2 for p in found if p is not o),
                default=math.inf,
            )

        return sorted(found, key=lambda o: -gap(o))
    return sorted(found, key=lambda o: math.hypot(o.x, o.y))
