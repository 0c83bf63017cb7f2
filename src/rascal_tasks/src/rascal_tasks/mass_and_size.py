"""What a sherd's size as the wrist camera measured it (length, width, wall) says its mass can
be, both ways: more than one sherd of that size can weigh is two sherds in one grasp; less than
one wall of that thickness can weigh means the wall was not one wall. No ROS in here.

Figures: shared/facts/sherds_and_colour.md §2 (fired clay 1.5-2.3 g/cm^3; apparent densities of
archaeological wares 1.77-1.87 g/cm^3, §2c, which suggests 1.7-2.0 for earthenware).
"""

from rascal_tasks.rig import Observation

# The most one sherd of a measured size can weigh: its whole bounding box (an outline fills
# 60-85 % of it) at the wall thickness, curved (up to ~10 % more surface), of the densest ware.
DENSEST_WARE = 2300.0  # kg/m^3
CURVED_SURFACE = 1.1
# The least: the outline filling 60 % of its box, of the lightest ware, less 15 % for what the
# wrist camera gets wrong (length and width ~1 mm, a 3 mm wall 0.24 mm at p95: perception
# README). Wares of 1.77-1.87 g/cm^3 measured on 480 sherds leave room below.
LIGHTEST_WARE = 1700.0  # kg/m^3
LEAST_FILL = 0.6
SIZE_ERRORS = 0.85


def more_than_one_sherd(o: Observation, kg: float) -> str:
    """Why `kg` is more than one sherd of the size the wrist camera measured (`o`) can weigh,
    or "" (also when its wall was not measured)."""
    if o is None or o.thickness <= 0.0:
        return ""
    most = o.length * o.width * o.thickness * CURVED_SURFACE * DENSEST_WARE
    if kg <= most:
        return ""
    return (
        "two sherds in one grasp? %.1f g is more than one sherd of %.0f x %.0f mm with a "
        "%.1f mm wall can weigh (%.1f g at most)"
        % (kg * 1000, o.length * 1000, o.width * 1000, o.thickness * 1000, most * 1000)
    )


def wall_heavier_than(o: Observation, kg: float) -> str:
    """Why the wall the wrist camera measured (`o.thickness`) cannot be one wall of a sherd of
    `kg` and `o`'s length and width, or "". In a heap the depth gives the lowest point of a
    sherd's top above the table: lying on another sherd it could not tell apart (one outline
    from above), that includes the sherd under it (heap_20 seed 59: walls of 18-35 mm recorded
    for sherds of 5-12 mm)."""
    if o is None or o.thickness <= 0.0 or kg <= 0.0:
        return ""
    per_metre = o.length * o.width * LEAST_FILL * LIGHTEST_WARE * SIZE_ERRORS  # kg per m of wall
    if per_metre <= 0.0 or kg >= per_metre * o.thickness:
        return ""
    return (
        "the wrist camera's %.1f mm wall is more than a %.1f g sherd of %.0f x %.0f mm can "
        "have (%.1f mm at most): measured where it lay on something seen as part of it"
        % (o.thickness * 1000, kg * 1000, o.length * 1000, o.width * 1000, kg / per_metre * 1000)
    )
