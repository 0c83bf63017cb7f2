"""Colour correction of an archival photo from the 24 chart patches (colour-science).

The photo's sRGB is decoded to linear RGB; each channel's tone curve (what the camera's white
balance, gamma and picture style did) is taken out with the six grey patches; a correction
fitted from the patches' linearised RGB to their published values (CIE L*a*b* D50 -> XYZ ->
Bradford to D65 -> linear sRGB) maps every pixel to linear sRGB under D65. Patches that clip
(any channel at 0 or 255 over part of the patch) are left out of the fit. The chart's accuracy
after correction is the mean CIEDE2000 of the 24 patches against their published L*a*b* (D50).
No ROS here.
"""

import glob
import os
import sys
import warnings
from dataclasses import dataclass

import numpy as np

WORKSPACE = os.path.abspath(os.path.join(os.path.dirname(__file__), *[".."] * 5))


def _import_colour():
    """colour-science, from the workspace's .venv when run by /usr/bin/python3 (rosrun): its
    site-packages appended, so Debian's numpy and cv2 stay first."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # colour-science warns once that matplotlib is missing
        try:
            import colour as c
        except ImportError:
            for path in glob.glob(
                os.path.join(WORKSPACE, ".venv", "lib", "python3*", "site-packages")
            ):
                if path not in sys.path:
                    sys.path.append(path)
            import colour as c
    return c


colour = _import_colour()

from rascal_tasks.archival.chart import chart_reference_lab  # noqa: E402

SRGB = colour.RGB_COLOURSPACES["sRGB"]
D50 = colour.CCS_ILLUMINANTS["CIE 1931 2 Degree Standard Observer"]["D50"]
D65 = colour.CCS_ILLUMINANTS["CIE 1931 2 Degree Standard Observer"]["D65"]
C = colour.CCS_ILLUMINANTS["CIE 1931 2 Degree Standard Observer"]["C"]
METHOD = "Cheung 2004"  # 3 x 3 matrix (terms=3): exact for a diagonal light and a linear camera
TERMS = 3
CLIP_SHARE = 0.02  # a patch with more than this share of clipped pixels is left out of the fit
TONE_CURVES = ("full", "power", "none")  # fit()'s choices; the others are for comparisons


def decode(srgb8: np.ndarray) -> np.ndarray:
    """8-bit (or 0..255 float) sRGB -> linear RGB [0, 1]."""
    return colour.cctf_decoding(np.asarray(srgb8, dtype=np.float64) / 255.0, function="sRGB")


def encode(linear: np.ndarray) -> np.ndarray:
    """linear RGB -> 8-bit sRGB (clipped)."""
    v = colour.cctf_encoding(np.clip(linear, 0.0, 1.0), function="sRGB")
    return np.clip(np.round(v * 255.0), 0, 255).astype(np.uint8)


def linear_srgb_to_xyz_d65(rgb: np.ndarray) -> np.ndarray:
    return np.asarray(rgb, dtype=np.float64) @ SRGB.matrix_RGB_to_XYZ.T


def xyz_to_lab(xyz: np.ndarray, white_xy) -> np.ndarray:
    return colour.XYZ_to_Lab(xyz, white_xy)


def adapt(xyz: np.ndarray, from_xy, to_xy) -> np.ndarray:
    return colour.chromatic_adaptation(
        xyz,
        colour.xy_to_XYZ(from_xy),
        colour.xy_to_XYZ(to_xy),
        method="Von Kries",
        transform="Bradford",
    )


def linear_to_lab_d50(rgb: np.ndarray) -> np.ndarray:
    """Linear sRGB (D65) -> CIE L*a*b* under D50 (Bradford), the catalogue's Lab."""
    return xyz_to_lab(adapt(linear_srgb_to_xyz_d65(rgb), D65, D50), D50)


def reference_linear() -> np.ndarray:
    """The 24 patches' published L*a*b* (D50) as linear sRGB (D65), 24 x 3 (unclipped)."""
    xyz50 = colour.Lab_to_XYZ(chart_reference_lab(), D50)
    xyz65 = adapt(xyz50, D50, D65)
    return xyz65 @ SRGB.matrix_XYZ_to_RGB.T


def delta_e00(lab1, lab2) -> np.ndarray:
    return colour.delta_E(lab1, lab2, method="CIE 2000")


NEUTRALS = slice(18, 24)  # the chart's bottom row: white 9.5 ... black 2
MIN_NEUTRALS = 4  # unclipped grey patches needed to fit the tone curve (else none is fitted)
GAMMA_RANGE = (0.5, 2.0)  # a fitted exponent outside this is not a camera's: none is used


@dataclass
class Correction:
    """A fitted correction: apply() maps linear camera RGB to linear sRGB (D65): first each
    channel's tone curve (gain x value^gamma, from the grey patches), then the matrix."""

    matrix: np.ndarray  # the terms -> RGB matrix of colour-science's correction
    used: np.ndarray  # bool, 24: patches the fit used
    delta_e00: np.ndarray  # per patch, after correction (all 24)
    gain: np.ndarray = None  # per channel (None: no tone curve)
    gamma: np.ndarray = None
    # per channel: the greys' log values and the power law's log residual there (the S of a
    # picture style, interpolated between the greys, held beyond them)
    knots: list = None

    @property
    def mean_delta_e00(self) -> float:
        return float(np.mean(self.delta_e00))

    def linearise(self, linear: np.ndarray) -> np.ndarray:
        if self.gain is None:
            return linear
        x = np.log(np.clip(linear, 1e-6, None))
        out = self.gain * np.exp(self.gamma * x)
        if self.knots is not None:
            for c, (kx, ky) in enumerate(self.knots):
                out[..., c] *= np.exp(np.interp(x[..., c], kx, ky))
        return out

    def apply(self, linear: np.ndarray) -> np.ndarray:
        return colour.characterisation.apply_matrix_colour_correction(
            self.linearise(linear), self.matrix, method=METHOD, terms=TERMS
        )


def fit_tone_curve(measured: np.ndarray, used: np.ndarray, ref: np.ndarray):
    """(gain, gamma, knots) per channel mapping the grey patches' decoded values onto their
    published linear values: a straight line in log-log (least squares; white balance and
    gamma) and the greys' residuals from it, interpolated (a picture style's S-curve).
    (None,) * 3 when too few greys are usable or the fit is no camera's; the matrix alone then
    corrects."""
    grey = np.zeros(len(measured), bool)
    grey[NEUTRALS] = True
    ok = grey & used & np.all(measured > 1e-3, axis=1)
    if ok.sum() < MIN_NEUTRALS:
        return None, None, None
    gain, gamma, knots = np.ones(3), np.ones(3), []
    for c in range(3):
        x, y = np.log(measured[ok, c]), np.log(np.clip(ref[ok, c], 1e-4, None))
        g, a = np.polyfit(x, y, 1)
        if not GAMMA_RANGE[0] <= g <= GAMMA_RANGE[1] or np.any(np.diff(x[np.argsort(y)]) <= 0):
            return None, None, None  # greys out of order: no camera's curve
        gain[c], gamma[c] = np.exp(a), g
        order = np.argsort(x)
        knots.append((x[order], (y - (a + g * x))[order]))
    return gain, gamma, knots


def fit(
    patches_srgb8: np.ndarray, clipped_share: np.ndarray, tone_curve: str = "full"
) -> Correction:
    """Fit the correction from the patches' measured 8-bit sRGB (24 x 3, chart order).
    `tone_curve`: "full" (the greys' power law and its interpolated residuals, then the
    matrix), "power" (the power law only) or "none" (the matrix alone): the last two are
    there to measure what the curve brings (bench/archival_colour --tone-curve)."""
    if tone_curve not in TONE_CURVES:
        raise ValueError("tone_curve %r: expected one of %s" % (tone_curve, ", ".join(TONE_CURVES)))
    measured = decode(patches_srgb8)
    used = np.asarray(clipped_share) <= CLIP_SHARE
    if used.sum() < 8:
        raise ValueError("colour chart: only %d of 24 patches unclipped, need 8" % used.sum())
    ref = reference_linear()
    gain, gamma, knots = (
        fit_tone_curve(measured, used, ref) if tone_curve != "none" else (None,) * 3
    )
    if tone_curve == "power":
        knots = None
    corr = Correction(np.eye(3), used, np.zeros(24), gain, gamma, knots)
    corr.matrix = colour.characterisation.matrix_colour_correction(
        corr.linearise(measured[used]), ref[used], method=METHOD, terms=TERMS
    )
    corr.delta_e00 = delta_e00(linear_to_lab_d50(corr.apply(measured)), chart_reference_lab())
    return corr


def correct_image(rgb8: np.ndarray, corr: Correction) -> np.ndarray:
    """The colour-corrected 8-bit sRGB image (a new array; the input is not changed)."""
    lut = decode(np.arange(256))  # decode by table: a 2000 x 1500 photo in a blink
    lin = lut[rgb8]
    out = np.empty(rgb8.shape, np.uint8)
    for y0 in range(0, rgb8.shape[0], 256):
        out[y0 : y0 + 256] = encode(corr.apply(lin[y0 : y0 + 256]))
    return out
