"""CLEAR MOT scores of the tracker on recorded tracks: exact counts on hand-made walks."""

from __future__ import annotations

import numpy as np
import pytest

from anyplan.experiments.tracking_eval import evaluate_tracking
from anyplan.prediction.detection import Detection
from anyplan.prediction.tracking import TrackerConfig
from anyplan.simulation.perception import Sensor


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
    assert a.gt == 82  # 41 frames, both people present in each (clutter and misses aside)
    assert a.started > 2  # clutter started young tracks
    assert a.tp >= 0.8 * a.gt  # yet the two people are followed most of the time
    with pytest.raises(ValueError, match="association"):
        evaluate_tracking(tracks, association="guess")


def test_a_crossing_with_a_miss_a_false_detection_and_swapped_labels_scores_as_counted_by_hand(
        monkeypatch):
    # Two people 4 s, 0.4 s samples: P1 along the x axis, P2 along the y axis, crossing the
    # origin 0.4 s after P1 (their closest approach, at 2.2 s, is 0.34 m: no tie in the matching)
    t = np.arange(0.0, 4.01, 0.4)
    p1 = np.column_stack([t, -2.4 + 1.2 * t, np.zeros_like(t)])
    p2 = np.column_stack([t, np.zeros_like(t), -2.88 + 1.2 * t])

    def at(tr, s):
        return float(np.interp(s, tr[:, 0], tr[:, 1])), float(np.interp(s, tr[:, 0], tr[:, 2]))

    def scripted(self, s, robot):
        """Exact named detections, but for three scripted faults (frames at 10 Hz)."""
        k = round(s * 10)
        a, b = at(p1, s), at(p2, s)
        if k >= 25:  # after the crossing the labels are swapped: "1" follows P2, "2" follows P1
            a, b = b, a
        dets = [Detection("2", s, *b, 0.25)]
        if k != 10:  # P1 is not detected at 1.0 s
            dets.append(Detection("1", s, *a, 0.25))
        if k == 30:  # one false detection at 3.0 s, over 2 m from both people
            dets.append(Detection("ghost", s, -2.0, 1.5, 0.25))
        return (), tuple(dets)

    monkeypatch.setattr(Sensor, "observe", scripted)
    tc = TrackerConfig(sigma_m=0.001, drop_after_s=0.05)  # a track unseen for a frame goes
    m = evaluate_tracking({1: p1, 2: p2}, association="named", noise_m=0.0, tracker=tc)
    # By hand: 41 frames (0 to 4 s at 10 Hz), 2 people in each: 82 people-frames.
    # FN = 1: at 1.0 s track "1" is dropped (unseen 0.1 s > 0.05 s) and P1 is matched to
    #   nothing; at 1.1 s "1" starts again, the same name, so no identity switch.
    # FP = 1: the ghost's track is reported at 3.0 s only (dropped at 3.1 s).
    # IDSW = 2: at 2.5 s P1 goes from track "1" to "2" and P2 from "2" to "1"; no other change.
    # TP = 82 - 1 = 81, MOTA = 1 - (1 + 1 + 2) / 82 = 78 / 82.
    assert (m.frames, m.gt, m.tp, m.fn, m.fp, m.id_switches) == (41, 82, 81, 1, 1, 2)
    assert m.mota == pytest.approx(78 / 82, abs=1e-12)


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
