"""CLEAR MOT scores of the tracker on recorded tracks: exact counts on hand-made walks."""

from __future__ import annotations

import numpy as np
import pytest

from anyplan.experiments.tracking_eval import evaluate_tracking
from anyplan.prediction.tracking import TrackerConfig


def _walks():
    """Two people 4 s each, 0.4 s samples: one along x, one along y, crossing at 2 s."""
    t = np.arange(0.0, 4.01, 0.4)
    a = np.column_stack([t, -2.4 + 1.2 * t, np.zeros_like(t)])
    b = np.column_stack([t, np.zeros_like(t), -2.4 + 1.2 * t])
    return {1: a, 2: b}


def test_exact_detections_give_exact_counts():
    tracks = _walks()
    tc = TrackerConfig(sigma_m=0.001, drop_after_s=0.05)
    named = evaluate_tracking(tracks, association="named", noise_m=0.0, tracker=tc)
    # 41 frames at 10 Hz, both people present in each: everyone matched, nothing else
    assert (named.frames, named.gt, named.tp, named.fn, named.fp) == (41, 82, 82, 0, 0)
    assert named.id_switches == 0 and named.mota == 1.0 and named.motp_m < 1e-6
    for hits in (2, 3):
        anon = evaluate_tracking(tracks, association="anonymous", noise_m=0.0,
                                 tracker=TrackerConfig(sigma_m=0.001, drop_after_s=0.05,
                                                       confirm_hits=hits))
        # a track is reported from its confirming detection: hits - 1 misses per person
        miss = 2 * (hits - 1)
        assert (anon.tp, anon.fn, anon.fp, anon.id_switches) == (82 - miss, miss, 0, 0)
        assert anon.mota == pytest.approx(1.0 - miss / 82) and anon.started == 2


def test_clutter_and_misses_cost_what_the_counts_say_and_repeat():
    tracks = _walks()
    a = evaluate_tracking(tracks, detection_prob=0.8, clutter_rate=1.0, seed=4)
    b = evaluate_tracking(tracks, detection_prob=0.8, clutter_rate=1.0, seed=4)
    assert a == b
    assert a.gt == a.tp + a.fn
    assert a.mota == pytest.approx(1.0 - (a.fn + a.fp + a.id_switches) / a.gt)
    assert a.started > 2  # clutter started young tracks
    assert a.tp >= 0.8 * a.gt  # yet the two people are followed most of the time
    with pytest.raises(ValueError, match="association"):
        evaluate_tracking(tracks, association="guess")


def test_a_person_who_leaves_in_view_is_not_counted_as_a_false_track_for_long():
    tracks = _walks()
    tracks[2] = tracks[2][tracks[2][:, 0] <= 1.2 + 1e-9]  # person 2 leaves the recording at 1.2 s
    tc = {"sigma_m": 0.001, "drop_after_s": 2.0}
    quick = evaluate_tracking(tracks, association="named", noise_m=0.0,
                              tracker=TrackerConfig(**tc, visible_misses=3))
    slow = evaluate_tracking(tracks, association="named", noise_m=0.0,
                             tracker=TrackerConfig(**tc, visible_misses=0))
    # missed at 1.3 and 1.4 s (false tracks), dropped at the third miss (1.5 s); without
    # negative information it coasts 2 s, until 3.2 s: 20 frames
    assert (quick.fp, slow.fp) == (2, 20)
    assert quick.tp == slow.tp == 41 + 13 and quick.fn == slow.fn == 0
