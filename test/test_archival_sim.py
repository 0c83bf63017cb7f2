"""End to end on the simulator's archival view: a scenario sherd of known Munsell chip and
outline, rendered under a warm light by rascal_sim (tool render_views: the shipped station
layout, the chart drawn from its published values), analysed as the recorder does."""

import os
import subprocess

import numpy as np
import pytest

from rascal_tasks.archival import Geometry, analyse
from rascal_tasks.archival.chart import BarSpec, ChartSpec
from rascal_tasks.archival.munsell import soil_chart, within_one_chip

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
RENDER = os.path.join(ROOT, "devel", "lib", "rascal_sim", "render_views")

# a 60 x 36 mm rectangle with its corners cut: extents along its principal axes 60 x 36 mm
OUTLINE = [[-0.030, -0.012], [-0.024, -0.018], [0.024, -0.018], [0.030, -0.012],
           [0.030, 0.012], [0.024, 0.018], [-0.024, 0.018], [-0.030, 0.012]]  # fmt: skip
SCENARIO = """name: archival_e2e
seed: 5
lighting:
  brightness: 0.8
  colour_temperature: 3600
  colour_noise: 2.0
  shadow: {strength: 0.0, radius: 0.05, start: [0.0, 0.45], velocity: [0.0, 0.0]}
sherds:
  - name: s
    pose: [0.08, 0.25, 0.0]
    outline: %s
    thickness: 0.008
    curvature: 6.0
    density: 1850
    munsell: "2.5YR 5/6"
""" % (OUTLINE,)


@pytest.mark.skipif(not os.access(RENDER, os.X_OK), reason="rascal_sim not built (make test)")
def test_simulated_archival_photo_gives_chip_scale_and_size(tmp_path):
    yaml = tmp_path / "s.yaml"
    yaml.write_text(SCENARIO)
    subprocess.run([RENDER, str(yaml), str(tmp_path)], check=True, capture_output=True, timeout=60)
    photo = tmp_path / "sim_archival.png"
    before = photo.read_bytes()
    geometry = Geometry(ChartSpec(70.0, 45.0), BarSpec(100.0, 15.0), camera_height_m=0.55)
    r = analyse(str(photo), geometry=geometry, wrist_size_mm=(60.5, 36.5), object_height_m=0.008)
    assert photo.read_bytes() == before  # only read
    assert r.flags == [], r.flags
    assert r.chart_de00 < 1.5 and r.chart_reprojection_px < 1.5 and r.bar_reprojection_px < 1.5
    assert within_one_chip(soil_chart().chip(r.munsell), soil_chart().chip("2.5YR 5/6"))
    assert r.munsell == "2.5YR 5/6"
    assert np.hypot(r.length_mm - 60.0, r.width_mm - 36.0) < 1.0, (r.length_mm, r.width_mm)
    # the view is 2000 px across 0.26 m of table: about 77 px/cm at the bar
    assert 70 < r.px_per_cm < 85
