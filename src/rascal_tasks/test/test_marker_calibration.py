"""Unit tests of marker_calibration (no ROS): markers drawn by OpenCV into a pinhole camera's
view of a moved and turned station are found, cast onto the table and give the station's pose;
the corrected site file moves what belongs to a station and nothing else; refusals name the key.
"""

import math
import os

import cv2
import numpy as np
import pytest
import yaml

from rascal_tasks import marker_calibration as mc
from rascal_tasks import site_file
from rascal_tasks.config import ConfigError, config_from_dict, load_config

WORKSPACE = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(__file__))))
SHIPPED = os.path.join(WORKSPACE, "config", "rascal.yaml")
K = np.array([[615.0, 0.0, 320.0], [0.0, 615.0, 240.0], [0.0, 0.0, 1.0]])


def _turn(a):
    return np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])


def camera_looking_down(x, y, height, yaw):
    """Optical frame (z forward, x right, y down) over (x, y) looking straight down."""
    # optical z = -base z; optical x turned by yaw in the table plane; y = z cross x
    ox = np.array([math.cos(yaw), math.sin(yaw), 0.0])
    oz = np.array([0.0, 0.0, -1.0])
    oy = np.cross(oz, ox)
    return np.column_stack([ox, oy, oz]), np.array([x, y, height])


def render(markers_on_table, rotation, translation, size=(480, 640)):
    """A grey table with each marker (id, 4 x 2 corners [m] in OpenCV's order) drawn on it."""
    img = np.full(size + (3,), 140, np.uint8)
    dictionary = cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_4X4_50)
    for marker_id, corners in markers_on_table:
        px = 600
        tile = np.full((px * 8 // 6, px * 8 // 6), 242, np.uint8)  # one cell of white margin
        tile[px // 6 : px // 6 + px, px // 6 : px // 6 + px] = cv2.aruco.drawMarker(
            dictionary, marker_id, px
        )
        c = np.asarray(corners)
        centre = c.mean(axis=0)
        outer = centre + (c - centre) * 8 / 6  # the margin's corners
        pts3 = np.column_stack([outer, np.zeros(4)])
        cam = (pts3 - translation) @ rotation  # base -> optical
        uv = (cam @ K.T)[:, :2] / cam[:, 2:3]
        src = np.float32(
            [[0, 0], [tile.shape[1], 0], [tile.shape[1], tile.shape[0]], [0, tile.shape[0]]]
        )
        h = cv2.getPerspectiveTransform(src, np.float32(uv))
        warped = cv2.warpPerspective(tile, h, (size[1], size[0]), flags=cv2.INTER_AREA)
        mask = cv2.warpPerspective(np.full(tile.shape, 255, np.uint8), h, (size[1], size[0]))
        img[mask > 127] = cv2.cvtColor(warped, cv2.COLOR_GRAY2BGR)[mask > 127]
    return img


def spec(centre=(0.30, 0.0), offsets=((-0.115, -0.05), (-0.115, 0.05)), ids=(2, 3)):
    return mc.StationMarkers(
        "scale", centre, tuple(mc.MarkerSpec(i, o) for i, o in zip(ids, offsets, strict=True))
    )


def true_corners(s, shift, turn):
    """Corners on the table of a station moved by `shift` and turned by `turn` about its centre."""
    out = []
    for m in s.markers:
        local = mc.marker_corners(m.offset) @ _turn(turn).T
        out.append((m.id, local + np.add(s.centre, shift)))
    return out


@pytest.mark.parametrize(
    "shift, turn",
    [((0.0, 0.0), 0.0), ((0.021, -0.013), math.radians(1.5)), ((-0.03, 0.03), math.radians(-5.0))],
)
def test_a_moved_and_turned_station_is_measured_within_the_targets(shift, turn):
    s = spec()
    markers = true_corners(s, shift, turn)
    seen = {}
    for i, marker in enumerate(s.markers):
        x, y = s.marker_position(i)  # the camera goes where the file says the marker is
        rot, trans = camera_looking_down(x + 0.01, y - 0.02, 0.31, math.atan2(y, x))
        found = mc.detect_markers(render(markers, rot, trans))
        assert marker.id in found
        seen[marker.id] = mc.pixels_to_table(found[marker.id], K, None, rot, trans)
    pose = mc.station_pose(s, seen)
    assert pose.shift == pytest.approx(shift, abs=0.0005)  # target 2 mm
    assert pose.turn == pytest.approx(turn, abs=math.radians(0.1))  # target 0.5°
    assert abs(pose.marker_distance_error) < 0.0005
    assert pose.confirmed() == (shift == (0.0, 0.0) and turn == 0.0)


def test_fit_pose_recovers_an_exact_motion():
    p = np.array([[0.0, 0.0], [0.1, 0.0], [0.0, 0.05], [0.07, 0.02]])
    q = p @ _turn(0.3).T + [0.2, -0.1]
    x, y, turn, residual = mc.fit_pose(p, q)
    assert (x, y, turn) == pytest.approx((0.2, -0.1, 0.3))
    assert residual < 1e-12


def test_a_missing_marker_is_named_with_its_station():
    s = spec()
    seen = {2: mc.marker_corners((0.0, 0.0))}
    with pytest.raises(mc.CalibrationError, match=r"stations\.scale: marker 3 not found"):
        mc.station_pose(s, seen)


def _pose(shift=(0.0, 0.0), turn=0.0, mismatch=0.0):
    return mc.StationPose(
        "discard", (0.02, -0.31), (0.02 + shift[0], -0.31 + shift[1]), turn, 0.0, mismatch
    )


def test_refusals_name_the_station_and_the_fix():
    mc.check_pose(_pose((0.03, 0.0), math.radians(5.0)))  # within what is corrected
    with pytest.raises(
        mc.CalibrationError,
        match=r"stations\.discard: turned 12\.0° clockwise.*turn it back anticlockwise",
    ):
        mc.check_pose(_pose(turn=math.radians(-12.0)))
    with pytest.raises(mc.CalibrationError, match=r"stations\.discard: the markers put it 60 mm"):
        mc.check_pose(_pose((0.06, 0.0)))
    with pytest.raises(mc.CalibrationError, match=r"marker_positions again"):
        mc.check_pose(_pose(mismatch=0.004))


def test_the_corrected_layout_moves_a_station_and_what_belongs_to_it_only():
    with open(SHIPPED, encoding="utf-8") as f:
        text = f.read()
    out = site_file.shift_stations(text, {"camera": (0.012, -0.0205), "scale": (-0.003, 0.0)})
    before, after = yaml.safe_load(text), yaml.safe_load(out)
    cam0, cam1 = before["stations"]["camera"], after["stations"]["camera"]
    for path in (
        ("position",),
        ("place_at",),
        ("colour_chart", "position"),
        ("scale_bar", "position"),
        ("stand", "position"),
    ):
        a, b = cam0, cam1
        for k in path:
            a, b = a[k], b[k]
        assert b == pytest.approx([a[0] + 0.012, a[1] - 0.0205], abs=1e-9), path
    assert cam1["size"] == cam0["size"] and cam1["marker_positions"] == cam0["marker_positions"]
    assert after["stations"]["scale"]["position"] == pytest.approx([0.297, 0.0])
    for name in ("pickup", "discard"):
        assert after["stations"][name] == before["stations"][name]
    assert {k: v for k, v in after.items() if k != "stations"} == {
        k: v for k, v in before.items() if k != "stations"
    }
    # comments and every other line as they were
    changed = [(a, b) for a, b in zip(text.splitlines(), out.splitlines(), strict=True) if a != b]
    assert len(changed) == 6, changed
    assert all("#" not in a or b.endswith(a[a.index("#") :]) for a, b in changed)


def _shipped():
    with open(SHIPPED, encoding="utf-8") as f:
        return yaml.safe_load(f)


def test_the_shipped_layout_has_markers_on_every_station():
    cfg = load_config(SHIPPED)
    assert [s.station for s in mc.stations_with_markers(cfg)] == [
        "pickup",
        "scale",
        "camera",
        "discard",
    ]


@pytest.mark.parametrize(
    "edit, message",
    [
        (
            lambda d: d["stations"]["scale"].pop("marker_positions"),
            r"stations\.scale\.marker_positions: missing",
        ),
        (
            lambda d: d["stations"]["scale"].update(marker_ids=[2, 1]),
            r"stations\.scale\.marker_ids: marker 1 is already on station pickup",
        ),
        (
            lambda d: d["stations"]["scale"].update(marker_ids=[2, 3.5]),
            r"stations\.scale\.marker_ids: expected whole",
        ),
        (
            lambda d: d["stations"]["scale"].update(marker_positions=[[0.0, 0.0], [-0.115, 0.05]]),
            r"scale\.marker_positions: the marker at \(0\.300, 0\.000\) lies on station scale",
        ),
        (
            lambda d: d["stations"]["scale"].update(marker_ids=[2, 60]),
            r"stations\.scale\.marker_ids",
        ),
    ],
)
def test_bad_markers_are_refused_naming_the_key(edit, message):
    data = _shipped()
    edit(data)
    with pytest.raises(ConfigError, match=message):
        config_from_dict(data)


def test_a_station_without_markers_is_fine():
    data = _shipped()
    for st in data["stations"].values():
        st.pop("marker_ids")
        st.pop("marker_positions")
    assert mc.stations_with_markers(config_from_dict(data)) == []


def test_the_printed_sheet_holds_every_configured_marker_at_40_mm():
    specs = mc.stations_with_markers(load_config(SHIPPED))
    page = mc.marker_sheet(specs, dpi=300)
    found = mc.detect_markers(cv2.cvtColor(page, cv2.COLOR_GRAY2BGR))
    assert sorted(found) == list(range(8))
    side = np.linalg.norm(found[0][1] - found[0][0])  # px between the outer black edges
    assert side / 300 * 0.0254 == pytest.approx(mc.MARKER_SIZE, abs=0.0002)


def test_a_turned_station_is_written_turned_with_everything_on_it():
    """move_stations turns the camera's places about its old centre and carries them to the
    measured one; its yaw is written as its own key (what `rascal calibrate` does at 5°)."""
    with open(SHIPPED, encoding="utf-8") as f:
        text = f.read()
    before = yaml.safe_load(text)["stations"]["camera"]
    old, new, turn = tuple(before["position"]), (0.33, -0.29), math.radians(5.0)
    out = site_file.move_stations(text, {"camera": (old, new, turn)})
    out = site_file.set_station_value(out, "camera", "yaw", turn)
    after = yaml.safe_load(out)["stations"]["camera"]
    assert after["position"] == pytest.approx(list(new), abs=1e-4)
    assert after["yaw"] == pytest.approx(turn, abs=1e-4)
    for key in ("place_at",):
        p = np.subtract(before[key], old) @ _turn(turn).T + new
        assert after[key] == pytest.approx(list(p), abs=1e-4)
    for part in ("colour_chart", "scale_bar", "stand"):
        p = np.subtract(before[part]["position"], old) @ _turn(turn).T + new
        assert after[part]["position"] == pytest.approx(list(p), abs=1e-4), part
        assert after[part]["size"] == before[part]["size"]
    cfg = config_from_dict(yaml.safe_load(out))  # the written layout loads, turned
    cam = cfg.stations["camera"]
    assert cam.area.yaw == pytest.approx(turn, abs=1e-4)
    assert cam.colour_chart.area.yaw == pytest.approx(turn, abs=1e-4)
    spec = next(s for s in mc.stations_with_markers(cfg) if s.station == "camera")
    x, y = spec.markers[0].offset
    assert spec.marker_position(0) == pytest.approx(tuple(cam.area.to_table((x, y))))
