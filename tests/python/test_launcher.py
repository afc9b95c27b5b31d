"""Unit tests of the launcher's own functions (scripts/rmslab_launcher): the
pieces that decide without running a process -- LCM URLs, terminal text,
the study's counterbalancing, the success interval, the sweep cache's
checks. The launcher's commands themselves are run for real by the C++
integration tests (tests/integration). Run: python3 -m pytest tests/python
(scripts/lint runs them; CONTRIBUTING.md "Lint")."""
import itertools
import json
import math
import os
import random
import sys

import pytest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "scripts"))

from rmslab_launcher import common, disk, study_file, study_stats, sweep_cache  # noqa: E402
from rmslab_launcher.common import LabError  # noqa: E402

SEED = 20261207  # the randomised tests' seed (printed by pytest -s)


@pytest.mark.parametrize("url", [common.DEFAULT_URL, "udpm://239.1.2.3:7667", "udpm://224.0.0.1:1?ttl=1"])
def test_an_lcm_url_the_processes_can_open_is_taken(url):
    common.check_lcm_url(url)


@pytest.mark.parametrize("url,said", [
    ("udpm://10.0.0.1:7667", "not an IPv4 multicast group"),
    ("udpm://240.0.0.1:7667", "not an IPv4 multicast group"),
    ("udpm://239.256.0.1:7667", "not an IPv4 multicast group"),
    ("udpm://239.1.2.3:0", "port 0 is not 1..65535"),
    ("udpm://239.1.2.3:70000", "port 70000 is not 1..65535"),
    ("tcpq://239.1.2.3:7667", "not udpm://GROUP:PORT"),
    ("udpm://239.1.2.3:7667?ttl=0;rm -rf", "not udpm://GROUP:PORT"),
])
def test_a_bad_lcm_url_is_refused_naming_what_is_wrong(url, said):
    with pytest.raises(LabError) as e:
        common.check_lcm_url(url)
    assert said in str(e.value)
    assert url in str(e.value)


def test_terminal_text_escapes_every_control_character_but_newline_and_tab():
    raw = "name\x1b]0;owned\x07\r\n\tend\x7f\x9b"
    safe = common.terminal_text(raw)
    assert safe == "name\\x1b]0;owned\\x07\\x0d\n\tend\\x7f\\x9b"
    assert all(c in "\n\t" or 0x20 <= ord(c) < 0x7f or ord(c) > 0x9f for c in safe)


@pytest.mark.parametrize("n", [2, 3, 4, 5, 6])
def test_the_balanced_latin_square_places_and_follows_each_condition_evenly(n):
    rows = study_file.balanced_latin_square(n)
    assert len(rows) == (n if n % 2 == 0 else 2 * n)
    for r in rows:
        assert sorted(r) == list(range(n))
    for place in range(n):  # each condition equally often in each place
        counts = [sum(r[place] == c for r in rows) for c in range(n)]
        assert len(set(counts)) == 1
    follows = {}  # each ordered pair of conditions equally often adjacent
    for r in rows:
        for a, b in zip(r, r[1:]):
            follows[(a, b)] = follows.get((a, b), 0) + 1
    assert set(follows) == {p for p in itertools.permutations(range(n), 2)}
    assert len(set(follows.values())) == 1


def test_condition_bindings_replace_the_control_tables_keys_only():
    text = "[rates]\nmode = \"kept\"\n[control]\nmode = \"single_joint\"\ncameras = [1]\nscale = \"fine\"\n"
    out = study_file.condition_bindings(text, {"control": "manual_augmented", "cameras": [4, 8]})
    lines = out.splitlines()
    assert lines.count('mode = "manual_augmented"') == 1
    assert 'mode = "kept"' in lines  # another table's key of the same name
    assert "cameras = [4, 8]" in lines and "cameras = [1]" not in lines
    assert 'scale = "fine"' in lines
    bare = study_file.condition_bindings("[rates]\n", {"control": "single_joint", "cameras": [2]})
    assert bare.splitlines()[-3:] == ["[control]", 'mode = "single_joint"', "cameras = [2]"]


def test_the_wilson_interval_holds_the_share_and_meets_its_closed_form():
    rng = random.Random(SEED)
    print(f"seed {SEED}")
    assert study_stats.wilson(0, 0) == (None, None, None)
    p, low, high = study_stats.wilson(0, 10)
    assert p == 0 and low == 0 and high == pytest.approx(0.2775, abs=1e-4)  # the textbook value
    for _ in range(200):
        n = rng.randint(1, 500)
        k = rng.randint(0, n)
        p, low, high = study_stats.wilson(k, n)
        assert 0.0 <= low <= p <= high <= 1.0
        # The bounds are the roots of (p - x)^2 = z^2 x (1 - x) / n.
        z = 1.959963984540054
        for x in (low, high):
            if 0 < x < 1:
                assert (p - x) ** 2 == pytest.approx(z * z * x * (1 - x) / n, rel=1e-9, abs=1e-12)


def test_a_session_needs_more_room_the_more_it_writes():
    small = disk.session_bytes_per_s(30, 160, 120, 0, False)
    assert small > 0
    assert disk.session_bytes_per_s(60, 160, 120, 0, False) > small
    assert disk.session_bytes_per_s(30, 640, 480, 1, False) > disk.session_bytes_per_s(30, 640, 480, 0, False)


def _result():
    outcome = {"acquired": True, "docked": False, "final_mode": 2, "collisions": 0, "held_frames": 0,
               "reached_s": {"acquired": 12.5}, "phase_durations_s": None, "docking": None}
    return {"outcome": outcome, "recorded_outcome": dict(outcome), "frames_identical": 10, "frames_compared": 10,
            "changes": [], "first_divergence": None}


def test_the_sweep_cache_gives_back_what_it_stored_and_refuses_what_was_edited(tmp_path):
    cache = sweep_cache.Cache(tmp_path)
    key = "ab" * 32
    assert cache.load(key) is None
    cache.store(key, _result())
    assert cache.load(key) == _result()
    entry = json.loads((tmp_path / f"{key}.json").read_text())
    entry["result"]["outcome"]["docked"] = True  # edited by hand
    (tmp_path / f"{key}.json").write_text(json.dumps(entry))
    assert cache.load(key) is None
    assert "does not match its checksum" in cache.unreadable[-1][1]
    other = "cd" * 32
    os.rename(tmp_path / f"{key}.json", tmp_path / f"{other}.json")
    assert cache.load(other) is None
    assert "another cell's entry" in cache.unreadable[-1][1]
    with pytest.raises(LabError):
        cache.path("../../etc/passwd")


@pytest.mark.parametrize("damage,why", [
    (lambda r: r.pop("frames_compared"), "'frames_compared' is missing"),
    (lambda r: r["outcome"].update(collisions=True), "'outcome.collisions'"),
    (lambda r: r.update(changes=[{"field": 3}]), "'changes'"),
    (lambda r: r.update(first_divergence={"frame": 1.5, "time_s": 0.1}), "'first_divergence' is of the wrong kind"),
])
def test_a_result_missing_a_field_or_of_the_wrong_kind_is_named(damage, why):
    assert sweep_cache.valid_result(_result()) is None
    r = _result()
    damage(r)
    said = sweep_cache.valid_result(r)
    assert said is not None and why in said


def test_numbers_are_numbers_and_a_bool_is_not_one():
    assert sweep_cache._number(1.5) and sweep_cache._number(None) and not sweep_cache._number(True)
    assert sweep_cache._integer(3) and not sweep_cache._integer(True) and not sweep_cache._integer(math.pi)
