"""The one frame loop (dcfkit.experiments.loop.steps, and track, which collects it) and the termination signals."""
from __future__ import annotations

import os
import signal

import numpy as np
import pytest

from dcfkit.experiments.loop import TrackerFailure, steps, track
from dcfkit.signals import Interrupted, interrupt_on_termination


class Stepper:
    """Moves the box 1 px right per update; raises on update ``fail_at`` (1-based frame)."""

    def __init__(self, fail_at=None, out=None, error=ValueError("boom")):
        self.fail_at, self.out, self.frame, self.error = fail_at, out, 1, error

    def init(self, image, box):
        self.box = np.asarray(box, float)

    def update(self, image):
        self.frame += 1
        if self.frame == self.fail_at:
            raise self.error
        self.box = self.box + [1, 0, 0, 0]
        return self.out if self.out is not None else self.box


FRAMES = [np.zeros((8, 8), np.uint8)] * 5


def test_track_collects_every_box_and_time():
    seen = []
    run = track(Stepper(), FRAMES, (1, 2, 3, 4), lambda i, image, box, t: seen.append((i, box[0])))
    np.testing.assert_array_equal(run.boxes[:, 0], [1, 2, 3, 4, 5])
    assert run.boxes.shape == (5, 4) and run.times.shape == (5,) and (run.times >= 0).all()
    assert seen == [(0, 1.0), (1, 2.0), (2, 3.0), (3, 4.0), (4, 5.0)]
    assert run.fps == pytest.approx(5 / run.times.sum())


def test_a_failure_names_the_frame_from_1_and_keeps_the_frames_before():
    done = []
    with pytest.raises(TrackerFailure, match=r"^frame 4: update raised ValueError: boom$") as caught:
        done.extend(steps(Stepper(fail_at=4), FRAMES, (1, 2, 3, 4)))
    assert caught.value.frame == 4 and isinstance(caught.value.__cause__, ValueError)
    assert [step.box[0] for step in done] == [1, 2, 3] and [step.index for step in done] == [0, 1, 2]


class Abort(BaseException):
    """A component's own BaseException subclass (not an interruption)."""


@pytest.mark.parametrize("error", [Abort("boom"), GeneratorExit("boom")])
def test_a_base_exception_of_a_component_fails_its_frame(error):
    done = []
    with pytest.raises(TrackerFailure, match=rf"^frame 3: update raised {type(error).__name__}: boom$"):
        done.extend(steps(Stepper(fail_at=3, error=error), FRAMES, (1, 2, 3, 4)))
    assert len(done) == 2


@pytest.mark.parametrize("error", [KeyboardInterrupt(), SystemExit(3), Interrupted(15)])
def test_interruptions_still_end_the_run(error):
    with pytest.raises(type(error)):
        track(Stepper(fail_at=2, error=error), FRAMES, (1, 2, 3, 4))


def test_a_non_box_is_a_failure_naming_the_frame():
    with pytest.raises(TrackerFailure, match=r"frame 2: update\(\) returned 'lost', expected 4 numbers"):
        track(Stepper(out="lost"), FRAMES, (1, 2, 3, 4))


@pytest.mark.parametrize("signame", ["SIGTERM", "SIGHUP"])
def test_termination_signals_interrupt_the_block_like_ctrl_c(signame):
    signum = getattr(signal, signame)
    # the signal's default action, whoever started the suite (nohup ignores SIGHUP, and an
    # ignored signal stays ignored: the next test)
    before = signal.signal(signum, signal.SIG_DFL)
    done = []

    def frames():
        for i, image in enumerate(FRAMES):
            if i == 2:
                os.kill(os.getpid(), signum)
            yield image

    try:
        with pytest.raises(Interrupted) as caught:
            with interrupt_on_termination():
                done.extend(steps(Stepper(), frames(), (1, 2, 3, 4)))
        assert isinstance(caught.value, KeyboardInterrupt) and caught.value.signum == signum
        assert len(done) == 2 and signal.getsignal(signum) == signal.SIG_DFL
    finally:
        signal.signal(signum, before)


def test_an_ignored_sighup_stays_ignored_as_under_nohup():
    previous = signal.signal(signal.SIGHUP, signal.SIG_IGN)
    try:
        with interrupt_on_termination():
            os.kill(os.getpid(), signal.SIGHUP)  # nothing happens
            assert signal.getsignal(signal.SIGHUP) is signal.SIG_IGN
        assert signal.getsignal(signal.SIGHUP) is signal.SIG_IGN
    finally:
        signal.signal(signal.SIGHUP, previous)


def test_termination_is_held_back_during_a_final_write():
    from dcfkit.signals import termination_deferred

    written = []
    with pytest.raises(Interrupted):
        with interrupt_on_termination():
            with termination_deferred():
                os.kill(os.getpid(), signal.SIGTERM)
                written.append("all of it")  # not cut short
    assert written == ["all of it"]


@pytest.mark.parametrize("box", [(1, 2, 3), "abc", None])
def test_a_malformed_initial_box_is_a_failure_of_frame_1(box):
    with pytest.raises(TrackerFailure, match=r"^frame 1: "):
        track(Stepper(), FRAMES, box)
