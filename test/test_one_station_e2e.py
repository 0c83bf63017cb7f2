"""End to end, the one-station layout (config/layouts/one_station.yaml loaded over the shipped
config, as `rosparam load` merges it): the real nodes started with rosrun, a real PostgreSQL
database, `rascal run` as a user types it. Each sherd is set down once on the scale under the
archival camera, weighed, photographed where it lies and dropped in the discard box; the photo's
analysis finds it on the scale's pan. Asserts outcomes, never timings."""

import os

import pytest
from rig_helpers import ground_truth, picked_sherd, rows, run_batch

from rascal_tasks import exit_codes

pytestmark = pytest.mark.timeout(900)
LAYOUT = os.path.join(
    os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
    "config",
    "layouts",
    "one_station.yaml",
)


def test_one_station_batch_weighs_and_photographs_each_sherd_where_it_lies(
    rig_factory, db, tmp_path
):
    rig = rig_factory(archive=tmp_path / "archive", over=[LAYOUT])
    truth = ground_truth(rig)
    code, out = run_batch(rig, db, "ONE-3")
    assert code == exit_codes.COMPLETE, out[-3000:] + rig.tail()
    recorded = rows(db, "ONE-3")
    assert [r["status"] for r in recorded] == ["done"] * 3, recorded
    # no carry from the scale to the camera: the states of the separate layout never ran
    assert "Place@camera" not in out and "Repick@scale" not in out, out[-2000:]
    names = set()
    for r in recorded:
        name = picked_sherd(truth, r)
        names.add(name)
        assert abs(r["mass_g"] - truth[name][2] * 1000) < 0.2, (r["seq"], name, r["mass_g"])
        # photographed on the pan: found there and measured, its colour read
        assert r["image_path"] and r["colour_munsell"], r
        notes = r["notes"] or ""
        assert "archival photo: L" in notes, notes
        assert "could not be placed" not in notes and "not found" not in notes, notes
    assert len(names) == 3
    # every sherd in the discard box at the end, none left on the scale
    after = ground_truth(rig)
    assert all(-0.06 < x < 0.10 and -0.40 < y < -0.22 for x, y, _ in after.values()), after
