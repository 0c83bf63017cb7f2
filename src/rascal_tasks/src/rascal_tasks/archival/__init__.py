"""Archival photo analysis: chart and scale bar located by features + homography, colour
correction from the chart, the sherd's Munsell chip and L*a*b*, its length and width in mm.
No ROS here (OpenCV, numpy, colour-science)."""

from rascal_tasks.archival.analysis import (
    ArchivalResult,
    Geometry,
    analyse,
    analyse_rgb,
    corrected_path,
    save_corrected,
)

__all__ = [
    "ArchivalResult",
    "Geometry",
    "analyse",
    "analyse_rgb",
    "corrected_path",
    "save_corrected",
]
