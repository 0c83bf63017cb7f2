"""End-to-end test of sorting (issue 17 item 7): sorting bins added to the shipped layout as
stations of type bin, the simulator builds them (walls and mat) from the same parameters, and
`rascal run` puts every sherd into the box its rule names on what the catalogue recorded of it.
A real master, the simulator, arm controller and detector started with rosrun, real PostgreSQL.
"""

import pytest
from rig_helpers import ground_truth, rows, run_batch

from rascal_tasks import exit_codes
from rascal_tasks.sorting import SherdValues, choose_bin, parse_rule

pytestmark = pytest.mark.timeout(900)

# Two bins in free places of the shipped layout (clear of the scale, the camera's view, the
# discard box and the arm's base). The rules do not overlap, so the order of the bins on the
# parameter server cannot change the answer; one of them needs the archival photo's colour.
BINS = {
    "small": ([0.14, -0.13], "length < 52 mm"),
    "dark": ([-0.08, -0.15], "length >= 52 mm and munsell_value <= 5"),
}
SIZE = [0.08, 0.08]


def _inside(xy, centre, size=SIZE):
    return all(abs(p - c) <= s / 2 for p, c, s in zip(xy, centre, size, strict=True))


def test_every_sherd_goes_into_the_box_its_rule_names(rig_factory, db, tmp_path):
    params = {
        "/stations/" + name: {
            "type": "bin",
            "position": xy,
            "size": SIZE,
            "surface_z": 0.0,
            "wall_height": 0.04,
            "rule": rule,
        }
        for name, (xy, rule) in BINS.items()
    }
    rig = rig_factory(archive=tmp_path / "archive", params=params)
    before = ground_truth(rig)
    code, out = run_batch(rig, db, "SORT-3")
    assert code == exit_codes.COMPLETE, out[-3000:] + rig.tail()
    after = ground_truth(rig)
    recorded = rows(db, "SORT-3")
    assert [r["status"] for r in recorded] == ["done"] * 3, recorded
    rules = [(name, parse_rule(rule)) for name, (_, rule) in BINS.items()]
    discard = ([0.02, -0.31], [0.14, 0.13])  # the shipped config's discard box
    boxes = {name: (xy, SIZE) for name, (xy, _) in BINS.items()}
    boxes["discard"] = discard
    for r in recorded:
        # the rule, applied to what the catalogue holds, names the box the row says
        want = choose_bin(rules, "discard", SherdValues.from_row(r)).bin
        assert r["bin"] == want, (r["seq"], r["length_mm"], r["colour_munsell"], r["bin"])
        # and the sherd lies in that box: the scenario sherd picked where this one was
        name = min(
            before,
            key=lambda n: (before[n][0] - r["pickup_x_m"]) ** 2
            + (before[n][1] - r["pickup_y_m"]) ** 2,
        )
        assert _inside(after[name][:2], *boxes[r["bin"]]), (name, r["bin"], after[name])
    # the 48 mm sherd goes to `small`, the two larger ones elsewhere: the test can fail
    assert sorted(r["bin"] == "small" for r in recorded) == [False, False, True], recorded
