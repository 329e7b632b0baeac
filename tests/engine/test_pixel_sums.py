"""rtpy.engine.pixel_sums: units added pass by pass whatever order they arrive in, and a
Ctrl-C at any bytecode leaving whole passes and a state a resumed render continues
from to the same image, bit for bit."""

from __future__ import annotations

import sys

import numpy as np
import pytest

from rtpy.engine.pixel_sums import PixelSums
from rtpy.engine.plan import Plan

from ..tiers import slow_except

PLAN = Plan(40, 20, 7, 64)  # passes of 1, 1, 2, 3 samples: 20, 20, 40 and 40 units


def unit_sums(plan: Plan, seed: int = 1) -> list:
    """Every unit of `plan` with sums of random values and magnitudes (so that the
    order of additions shows in the last bits)."""
    rng = np.random.default_rng(seed)
    out = []
    for unit in plan.units():
        shape = (unit.y1 - unit.y0, unit.x1 - unit.x0, 3)
        out.append((unit, rng.random(shape) * 10.0 ** rng.integers(-8, 8)))
    return out


def added(plan: Plan, items) -> PixelSums:
    sums = PixelSums(plan)
    for unit, s in items:
        sums.add(unit, s)
    return sums


def test_sums_do_not_depend_on_the_order_units_arrive_in():
    """Workers finish units in any order; adding them in pass order gives the same
    image bit for bit (adding in arrival order would not: float addition is not
    associative), and nothing is left waiting."""
    items = unit_sums(PLAN)
    in_order = added(PLAN, items)
    rng = np.random.default_rng(2)
    shuffled = PixelSums(PLAN)
    naive = np.zeros((20, 40, 3))
    for i in rng.permutation(len(items)):
        unit, s = items[i]
        shuffled.add(unit, s)
        naive[unit.y0 : unit.y1, unit.x0 : unit.x1] += s
    assert in_order.done and shuffled.done and not shuffled._waiting
    np.testing.assert_array_equal(shuffled.total, in_order.total)
    np.testing.assert_array_equal(shuffled.total[..., 3], 7)
    assert not np.array_equal(naive, in_order.total[..., :3])


def test_a_later_pass_waits_and_a_unit_added_twice_counts_once():
    items = unit_sums(PLAN)
    sums = PixelSums(PLAN)
    first, second = items[:20], items[20:40]
    assert not sums.add(*second[0])  # pass 1 before pass 0: it waits
    assert sums.paths() == 0 and len(sums._waiting) == 1
    for item in first:
        sums.add(*item)
    assert sums.passes == 1 and sums.whole_samples() == 1
    assert sums.samples_range() == (1, 2)  # the waiting unit is in the pass in progress
    sums.add(*first[0])  # a unit a cluster ran twice: ignored
    sums.add(*second[0])
    assert sums.samples_range() == (1, 2) and sums.whole_samples() == 1


def test_the_mean_is_of_whole_passes_and_the_snapshot_shows_the_pass_in_progress():
    items = unit_sums(PLAN)
    sums = added(PLAN, items[:21])  # pass 0 and a unit of pass 1
    snapshot = sums.snapshot()
    whole = sums.total[..., :3] / sums.total[..., 3:]
    u, s = items[20]
    part = snapshot[u.y0 : u.y1, u.x0 : u.x1]
    np.testing.assert_array_equal(part, (sums.total[u.y0 : u.y1, u.x0 : u.x1, :3] + s) / 2)
    np.testing.assert_array_equal(sums.mean(), whole)  # the unit of pass 1 is dropped


def interrupt_at(opcode: int):
    """A tracer raising KeyboardInterrupt (a Ctrl-C's) before the opcode-th bytecode
    that PixelSums' own methods execute, counting from 1."""
    seen = 0

    def tracer(frame, event, arg):
        nonlocal seen
        if event == "call":
            if frame.f_code.co_qualname.split(".")[0] != "PixelSums":
                return None
            frame.f_trace_opcodes = True
            return tracer
        if event == "opcode":
            seen += 1
            if seen == opcode:
                raise KeyboardInterrupt
        return tracer

    return tracer


@pytest.mark.parametrize("seed", slow_except([3, 4], 3))
def test_a_ctrl_c_at_any_bytecode_leaves_whole_passes_and_a_state_to_resume(seed):
    """Ctrl-C raises KeyboardInterrupt between any two bytecodes, also inside
    PixelSums.add. After it, `total` must hold whole passes (the counts equal), and
    a PixelSums rebuilt from total and current() (what a checkpoint keeps) that is
    given every unit again must end with the uninterrupted total, bit for bit."""
    plan = Plan(24, 6, 5, 48)  # passes of 1, 1, 2, 1 samples: 3, 3, 6 and 3 units
    items = unit_sums(plan, seed)
    order = [items[i] for i in np.random.default_rng(seed).permutation(len(items))]
    expected = added(plan, items).total
    for opcode in range(1, 100_000):
        sums = PixelSums(plan)
        sys.settrace(interrupt_at(opcode))
        try:
            for unit, s in order:
                sums.add(unit, s)
        except KeyboardInterrupt:
            interrupted = True
        else:
            interrupted = False
        finally:
            sys.settrace(None)
        counts = sums.total[..., 3]
        assert (counts == counts.flat[0]).all(), f"cut at bytecode {opcode}"
        assert plan.passes_holding(sums.whole_samples()) is not None
        assert sums.done == (sums.whole_samples() == plan.samples_after(len(plan.passes)))
        resumed = PixelSums(plan, sums.total.copy(), sums.current())
        for unit, s in order:
            resumed.add(unit, s)
        np.testing.assert_array_equal(resumed.total, expected, err_msg=f"cut at {opcode}")
        if not interrupted:
            assert opcode > 500 and sums.done  # every cut was tried
            break


def test_a_state_of_another_plan_is_refused():
    with pytest.raises(ValueError, match="passes of the plan"):
        PixelSums(PLAN, np.full((20, 40, 4), 3.0), np.zeros((20, 40, 5)))  # 3: no pass ends
    with pytest.raises(ValueError, match="passes of the plan"):
        PixelSums(PLAN, np.zeros((20, 41, 4)))
