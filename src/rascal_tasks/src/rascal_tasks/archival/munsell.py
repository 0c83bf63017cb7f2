"""Munsell notation of a colour under illuminant C, snapped to the soil-colour chart's chips.

The chips are the hue pages (10R .. 5Y and N) of data/munsell_soil_hues_grid_renotation.csv
(Munsell renotation xyY under illuminant C). A measured colour, linear sRGB under D65, is
adapted to C (Bradford), taken to CIE L*a*b* relative to C, and the chip nearest in CIEDE2000 is
its notation. `within_one_chip` is the agreement the benchmark counts: the same or a
neighbouring hue page, value within 1 step, chroma within 2. No ROS here.
"""

import csv
import os
from dataclasses import dataclass
from typing import List, Tuple

import numpy as np

from rascal_tasks.archival import colour as col
from rascal_tasks.archival.chart import DATA_DIR

CHIPS_CSV = os.path.join(DATA_DIR, "munsell_soil_hues_grid_renotation.csv")
HUE_PAGES = ["10R", "2.5YR", "5YR", "7.5YR", "10YR", "2.5Y", "5Y"]


@dataclass(frozen=True)
class Chip:
    notation: str
    hue: str  # page ('N' for neutrals)
    value: float
    chroma: float


class SoilChart:
    def __init__(self, path: str = CHIPS_CSV):
        chips, xyy = [], []
        with open(path, newline="") as f:
            for r in csv.DictReader(f):
                chips.append(Chip(r["munsell"], r["hue"], float(r["value"]), float(r["chroma"])))
                xyy.append([float(r["x_C"]), float(r["y_C"]), float(r["Y_C"])])
        self.chips: List[Chip] = chips
        self.lab_c = col.xyz_to_lab(col.colour.xyY_to_XYZ(np.array(xyy)), col.C)
        self.by_name = {c.notation: i for i, c in enumerate(chips)}

    def lab_c_of_linear(self, linear_rgb) -> np.ndarray:
        """Linear sRGB (D65) -> L*a*b* relative to illuminant C."""
        xyz = col.adapt(col.linear_srgb_to_xyz_d65(linear_rgb), col.D65, col.C)
        return col.xyz_to_lab(xyz, col.C)

    def nearest(self, linear_rgb) -> Tuple[Chip, float]:
        """The chip nearest to a linear sRGB colour, and its CIEDE2000 distance."""
        lab = self.lab_c_of_linear(linear_rgb)
        de = col.delta_e00(np.broadcast_to(lab, self.lab_c.shape), self.lab_c)
        i = int(np.argmin(de))
        return self.chips[i], float(de[i])

    def chip(self, notation: str) -> Chip:
        return self.chips[self.by_name[notation]]


_VALUES = [2.5, 3, 4, 5, 6, 7, 8]


def _value_step(v: float) -> int:
    return min(range(len(_VALUES)), key=lambda i: abs(_VALUES[i] - v))


def within_one_chip(a: Chip, b: Chip) -> bool:
    """Same or neighbouring hue page (a neutral matches any page at chroma <= 2), value
    within one step of the chart, chroma within 2."""
    if abs(_value_step(a.value) - _value_step(b.value)) > 1 or abs(a.chroma - b.chroma) > 2:
        return False
    if a.hue == "N" or b.hue == "N":
        return max(a.chroma, b.chroma) <= 2
    return abs(HUE_PAGES.index(a.hue) - HUE_PAGES.index(b.hue)) <= 1


_CHART = None


def soil_chart() -> SoilChart:
    global _CHART
    if _CHART is None:
        _CHART = SoilChart()
    return _CHART
