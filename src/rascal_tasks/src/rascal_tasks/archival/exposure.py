"""Exposure of the archival photo: when its highlights clip, shoot it again darker.

A channel at the top of its range says nothing more about the colour: a bright or saturated
sherd (an orange 8/8 under warm light clips red first) gets no Munsell, and near-clipped chart
patches bend the colour correction. The chart in the photo corrects a darker exposure fully, so
one stop less costs only a little noise on dark sherds. The camera is set by the site (the
configuration's exposure and white balance); the station only steps down from there, and keeps
the step for the next sherd of the batch (the light rarely changes within one), stepping back
up when a photo leaves more than a stop of headroom. No ROS here.
"""

from typing import Optional

import cv2
import numpy as np

# 8-bit codes at or above this are near clipping: a picture style's shoulder and the JPEG's
# rounding squeeze the top few codes, so a patch there reads too dark in its brightest channel.
NEAR_CLIP = 250
# More than this share of the photo's pixels near clipping asks for a darker photo: 0.1 % of a
# 2000 x 1500 photo is 3000 px, a tenth of a 25 mm sherd's face; a glint on a glaze is less.
RETAKE_SHARE = 0.001
# Headroom to step back up: the photo's brightest pixels (99.9th percentile of each pixel's
# highest channel; the chart's white patch is always in view) below this code are more than a
# stop from clipping (sRGB code 170 is 0.40 of full light: twice that still codes below 250).
HEADROOM_CODE = 170
STEP_EV = 1.0
# Beyond two stops dark sherds drown in noise; a glaze that still clips there is flagged.
DARKEST_EV = -2.0


class Brightness:
    """What the exposure rule needs of one photo."""

    def __init__(self, near_clip_share: float, top_code: float):
        self.near_clip_share = near_clip_share
        self.top_code = top_code

    def __repr__(self):
        return "Brightness(%.4f near clip, top %.0f)" % (self.near_clip_share, self.top_code)


def measure(path: str) -> Optional[Brightness]:
    """The photo's brightness figures, None when it cannot be read (the analysis says why)."""
    bgr = cv2.imread(path, cv2.IMREAD_COLOR)
    if bgr is None or bgr.size == 0:
        return None
    top = bgr.max(axis=2)
    return Brightness(
        float(np.count_nonzero(top >= NEAR_CLIP)) / top.size, float(np.percentile(top, 99.9))
    )


class Exposure:
    """The exposure [EV from the configured one] for the archival captures of one batch."""

    def __init__(self):
        self.ev = 0.0

    def retake(self, seen: Optional[Brightness]) -> Optional[float]:
        """After a photo at `self.ev`: the darker EV to shoot it again at (and remembered for the
        next sherds), or None when it stands (not clipped, unreadable, or already darkest)."""
        if seen is None or seen.near_clip_share <= RETAKE_SHARE or self.ev <= DARKEST_EV:
            return None
        self.ev = max(DARKEST_EV, self.ev - STEP_EV)
        return self.ev

    def settle(self, seen: Optional[Brightness]) -> None:
        """After the photo that stands: a stop brighter for the next sherd when this one had
        more than a stop of headroom (never above the configured exposure)."""
        if seen is not None and seen.near_clip_share == 0.0 and seen.top_code < HEADROOM_CODE:
            self.ev = min(0.0, self.ev + STEP_EV)
