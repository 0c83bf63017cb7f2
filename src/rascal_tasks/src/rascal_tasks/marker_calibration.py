"""Station poses from ArUco markers, instead of a ruler (issue 17 item 5). No ROS in here.

Each calibrated station carries two markers (`stations.<name>.marker_ids`,
`marker_positions`: their centres from the station's centre, in the station's frame). The wrist
camera looks straight down at each marker; its corners, found to a fraction of a pixel, are cast
as rays from the camera onto the table top (z = 0, where the markers lie), which is more exact
than the depth image. The two markers' eight corners against where the configuration puts them
give the station's centre and its turn (a least-squares rigid fit in the plane); the distance
between the two markers, which no move of the station changes, tells a marker that came loose.

The corrected layout is the site file with a moved station's places moved and turned with it
(`site_file.move_stations`: its centre, a taught place, and the archival camera's place_at,
chart, bar and stand with it) and its `yaw` written, every other line, comment and key as it
was. A station turned more than TURN_LIMIT from its configured yaw is not a ruler's error but a
knocked station: the operator turns it back.
"""

import math
from dataclasses import dataclass
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np

from rascal_tasks.planar import placed

# What is printed and stuck on (docs/markers: print at 100 %, 40 mm between the outer black
# edges; a white margin of one cell around it).
MARKER_SIZE = 0.040  # [m]
DICTIONARY = "DICT_4X4_50"  # 50 IDs of 4 x 4 bits: large cells, read from 0.3 m at 640 x 480
# A station moved farther than this, or markers disagreeing with each other by more, is not a
# ruler's error to correct but a wrong marker ID or position in the file: refused.
MAX_SHIFT = 0.05  # [m]
MAX_MARKER_MISMATCH = 0.003  # [m] measured vs configured distance between a station's markers
# A turn up to this is written as the station's yaw; more is refused (the 5° with room).
TURN_LIMIT = math.radians(10.0)  # [rad]
# Below these the configured layout is confirmed as it is (the accuracy targets).
POSITION_TOLERANCE = 0.002  # [m]
TURN_TOLERANCE = math.radians(0.5)  # [rad]


class CalibrationError(Exception):
    """One line naming the station or marker and what to do."""


@dataclass(frozen=True)
class MarkerSpec:
    id: int
    offset: Tuple[float, float]  # [m] centre from the station centre, station frame


@dataclass(frozen=True)
class StationMarkers:
    station: str
    centre: Tuple[float, float]  # [m] configured station centre in base_link
    markers: Tuple[MarkerSpec, MarkerSpec]
    yaw: float = 0.0  # [rad] the station's configured yaw (its frame in base_link)

    def marker_position(self, i: int) -> Tuple[float, float]:
        """Where the configuration puts marker i in base_link (the camera looks there)."""
        return placed(self.centre, self.yaw, self.markers[i].offset)


@dataclass(frozen=True)
class StationPose:
    station: str
    configured: Tuple[float, float]
    measured: Tuple[float, float]  # [m] the station's centre as the markers place it
    turn: float  # [rad] the station's yaw measured: about +z, counter-clockwise from above
    residual: float  # [m] RMS of the corners against the fitted pose
    marker_distance_error: float  # [m] measured minus configured distance between the markers
    configured_yaw: float = 0.0  # [rad] stations.<name>.yaw

    @property
    def turned(self) -> float:
        """[rad] how far it turned from its configured yaw."""
        return math.remainder(self.turn - self.configured_yaw, 2 * math.pi)

    @property
    def shift(self) -> Tuple[float, float]:
        return self.measured[0] - self.configured[0], self.measured[1] - self.configured[1]

    @property
    def shift_norm(self) -> float:
        return math.hypot(*self.shift)

    def confirmed(self) -> bool:
        return self.shift_norm <= POSITION_TOLERANCE and abs(self.turned) <= TURN_TOLERANCE


def stations_with_markers(cfg) -> List[StationMarkers]:
    """The stations of a checked configuration that carry markers, in the file's order."""
    out = []
    for name, st in cfg["stations"].items():
        ids, positions = st.get("marker_ids"), st.get("marker_positions")
        if ids is None:
            continue
        markers = tuple(
            MarkerSpec(int(i), (float(p[0]), float(p[1])))
            for i, p in zip(ids, positions, strict=True)
        )
        out.append(StationMarkers(name, tuple(st["position"]), markers, st.get("yaw", 0.0)))
    return out


def marker_sheet(specs: Sequence[StationMarkers], dpi: int = 300) -> np.ndarray:
    """A white page (A4 at `dpi`) with every configured marker at its printed size, its white
    margin, and below it its ID and station, to print at 100 % and cut out."""
    import cv2

    _, dictionary, _ = _aruco()
    px = int(round(MARKER_SIZE / 0.0254 * dpi))
    page = np.full((int(11.69 * dpi), int(8.27 * dpi)), 255, np.uint8)
    step = px * 3 // 2  # 60 mm: the marker, its margin and its label
    cols = max(1, (page.shape[1] - px // 2) // step)
    items = [(m.id, s.station) for s in specs for m in s.markers]
    for k, (marker_id, station) in enumerate(items):
        row, col = divmod(k, cols)
        x0, y0 = px // 2 + col * step, px // 2 + row * step
        if y0 + step > page.shape[0]:
            raise CalibrationError("more markers than fit on one page (%d)" % k)
        page[y0 : y0 + px, x0 : x0 + px] = cv2.aruco.drawMarker(dictionary, marker_id, px)
        cv2.putText(
            page,
            "%d %s, top edge to +y" % (marker_id, station),
            (x0, y0 + px + px // 4),
            cv2.FONT_HERSHEY_SIMPLEX,
            px / 400.0,
            0,
            max(1, px // 200),
        )
    return page


def marker_corners(offset: Sequence[float]) -> np.ndarray:
    """The four corners of a marker in the station frame, in OpenCV's order (top-left, top-right,
    bottom-right, bottom-left as printed; printed top = station +y, right = station +x)."""
    h = MARKER_SIZE / 2
    x, y = offset
    return np.array([[x - h, y + h], [x + h, y + h], [x + h, y - h], [x - h, y - h]])


def _aruco():
    import cv2

    dictionary = cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, DICTIONARY))
    if hasattr(cv2.aruco, "DetectorParameters_create"):  # OpenCV < 4.7 (Debian 12: 4.6)
        params = cv2.aruco.DetectorParameters_create()
    else:
        params = cv2.aruco.DetectorParameters()
    params.cornerRefinementMethod = cv2.aruco.CORNER_REFINE_SUBPIX
    return cv2, dictionary, params


def detect_markers(image_bgr: np.ndarray) -> Dict[int, np.ndarray]:
    """{marker id: its four corners in pixels (4 x 2)} of the markers found in a colour image.
    An ID seen twice in one image is left out (two markers printed with one ID)."""
    cv2, dictionary, params = _aruco()
    grey = cv2.cvtColor(image_bgr, cv2.COLOR_BGR2GRAY)
    if hasattr(cv2.aruco, "ArucoDetector"):
        corners, ids, _ = cv2.aruco.ArucoDetector(dictionary, params).detectMarkers(grey)
    else:
        corners, ids, _ = cv2.aruco.detectMarkers(grey, dictionary, parameters=params)
    found: Dict[int, np.ndarray] = {}
    twice = set()
    for c, i in zip(corners, [] if ids is None else ids.ravel(), strict=True):
        i = int(i)
        if i in found:
            twice.add(i)
        found[i] = c.reshape(4, 2).astype(float)
    for i in twice:
        del found[i]
    return found


def pixels_to_table(
    pixels: np.ndarray,
    camera_matrix: np.ndarray,
    distortion: Optional[np.ndarray],
    rotation: np.ndarray,
    translation: np.ndarray,
    z: float = 0.0,
) -> np.ndarray:
    """Pixels (N x 2) cast as rays from the camera onto the plane z (base_link): N x 2 [m].
    `rotation`, `translation`: the camera's optical frame in base_link."""
    import cv2

    pts = np.asarray(pixels, dtype=np.float64).reshape(-1, 1, 2)
    d = None if distortion is None or not np.any(distortion) else np.asarray(distortion)
    norm = cv2.undistortPoints(pts, np.asarray(camera_matrix, dtype=np.float64), d).reshape(-1, 2)
    rays = np.column_stack([norm, np.ones(len(norm))]) @ np.asarray(rotation).T
    if np.any(rays[:, 2] >= -1e-9):
        raise CalibrationError("the wrist camera does not look down at the table")
    s = (z - translation[2]) / rays[:, 2]
    return translation[:2] + rays[:, :2] * s[:, None]


def fit_pose(
    station_points: np.ndarray, table_points: np.ndarray
) -> Tuple[float, float, float, float]:
    """The rigid motion in the plane taking station-frame points onto measured ones:
    (x, y, turn, RMS residual); (x, y) is where the station frame's origin lands."""
    p = np.asarray(station_points, dtype=float)
    q = np.asarray(table_points, dtype=float)
    pc, qc = p.mean(axis=0), q.mean(axis=0)
    a, b = p - pc, q - qc
    turn = math.atan2(float(np.sum(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])), float(np.sum(a * b)))
    r = np.array([[math.cos(turn), -math.sin(turn)], [math.sin(turn), math.cos(turn)]])
    t = qc - r @ pc
    residual = float(np.sqrt(np.mean(np.sum((p @ r.T + t - q) ** 2, axis=1))))
    return float(t[0]), float(t[1]), turn, residual


def station_pose(spec: StationMarkers, seen: Dict[int, np.ndarray]) -> StationPose:
    """The station's pose from its markers' corners on the table (`seen`: id -> 4 x 2 [m])."""
    missing = [m.id for m in spec.markers if m.id not in seen]
    if missing:
        raise CalibrationError(
            "stations.%s: marker %d not found near %s; is it covered, or is its ID wrong in "
            "stations.%s.marker_ids?"
            % (
                spec.station,
                missing[0],
                _xy(spec.marker_position([m.id for m in spec.markers].index(missing[0]))),
                spec.station,
            )
        )
    station_pts = np.vstack([marker_corners(m.offset) for m in spec.markers])
    table_pts = np.vstack([seen[m.id] for m in spec.markers])
    x, y, turn, residual = fit_pose(station_pts, table_pts)
    configured = float(np.hypot(*np.subtract(spec.markers[0].offset, spec.markers[1].offset)))
    measured = float(
        np.hypot(*(seen[spec.markers[0].id].mean(0) - seen[spec.markers[1].id].mean(0)))
    )
    return StationPose(
        spec.station,
        (float(spec.centre[0]), float(spec.centre[1])),
        (x, y),
        turn,
        residual,
        measured - configured,
        spec.yaw,
    )


def check_pose(pose: StationPose) -> None:
    """Refuses (CalibrationError, one line) what a corrected position cannot mend."""
    key = "stations.%s" % pose.station
    if abs(pose.marker_distance_error) > MAX_MARKER_MISMATCH:
        raise CalibrationError(
            "%s: its markers are %.1f mm %s apart than marker_positions says; one came loose "
            "or was moved: measure %s.marker_positions again"
            % (
                key,
                abs(pose.marker_distance_error) * 1e3,
                "farther" if pose.marker_distance_error > 0 else "closer",
                key,
            )
        )
    if pose.shift_norm > MAX_SHIFT:
        raise CalibrationError(
            "%s: the markers put it %.0f mm from %s.position (more than %.0f mm): check the "
            "marker IDs and positions, or measure the station again"
            % (key, pose.shift_norm * 1e3, key, MAX_SHIFT * 1e3)
        )
    if abs(pose.turned) > TURN_LIMIT:
        raise CalibrationError(
            "%s: turned %.1f° %s from its configured yaw (at most %.0f° is taken); turn "
            "it back %s and run `rascal calibrate` again"
            % (
                key,
                abs(math.degrees(pose.turned)),
                "anticlockwise" if pose.turned > 0 else "clockwise",
                math.degrees(TURN_LIMIT),
                "clockwise" if pose.turned > 0 else "anticlockwise",
            )
        )


def _xy(p) -> str:
    return "(%.3f, %.3f)" % (p[0], p[1])
