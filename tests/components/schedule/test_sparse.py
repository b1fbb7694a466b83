"""Update schedules: ECO's sparse updates by frame number."""
from dcfkit.components.schedule import EveryFrame, Sparse
from dcfkit.registry import get_registry


def test_sparse_trains_every_frame_then_every_sixth():
    s = Sparse(Sparse.Params(gap=5, after_frame=10))
    due = [f for f in range(1, 40) if s.due(f)]
    # frames 1-9 train; from frame 10 a training needs 5 untrained frames before it (ECO's N_s = 6)
    assert due == [1, 2, 3, 4, 5, 6, 7, 8, 9, 15, 21, 27, 33, 39]
    s.reset()
    assert s.due(1)


def test_a_zero_gap_trains_every_frame():
    s = Sparse(Sparse.Params(gap=0, after_frame=1))
    assert all(s.due(f) for f in range(1, 20))
    assert all(EveryFrame().due(f) for f in range(1, 5))


def test_schedules_are_registered_as_their_kind():
    assert {"every_frame", "sparse"} <= set(get_registry().names("schedule"))
