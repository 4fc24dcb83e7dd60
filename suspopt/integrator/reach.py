"""The part of a network that a run's recorded rows depend on, for the compiled engine
(:func:`.compiled.windows`): which DOFs and elements to integrate (:func:`reached`), the
road's arrays of those elements alone, and the recorded rows renumbered among them.

A streamed evaluation records only the rows of the states and accelerations its signals read
(:func:`suspopt.streaming.recorded_rows`). Without a controller, only what those rows depend
on needs integrating: a one-way seat's DOFs do not reach the vehicle's, so objectives of the
vehicle alone need none of the seat. The kept rows' entries stay the same and in the same
order (:func:`.compiled._packed`), so their arithmetic, and their bits, are the same.
"""

from __future__ import annotations

import numpy as np

from ..network import Assembled

__all__ = ["reached", "reached_road", "renumbered"]


def reached(asm: Assembled, recorded: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """The DOFs and the elements (sorted indices) that the rows ``recorded (3n,)`` of the
    states ``[q; q']`` and accelerations depend on, or None when that is every DOF: a DOF's
    acceleration on the elements whose forces reach it (``G``), an element's force on the
    DOFs its deformation reads (``D_q``), closed. A one-way seat's DOFs are not reached from
    the vehicle's: an evaluation whose signals read only the vehicle does not integrate the
    seat (Part B of Ch. 6: 4 of 12 DOFs, 4 of 13 elements)."""
    n, R = asm.n, asm.R
    reads, pushes = asm.D2[..., :R, :n] != 0, asm.G2[..., :R] != 0
    reads = reads.any(axis=0) if reads.ndim == 3 else reads  # (R, n)
    pushes = pushes.any(axis=0) if pushes.ndim == 3 else pushes  # (n, R)
    dofs = recorded[:n] | recorded[n : 2 * n] | recorded[2 * n : 3 * n]
    while True:
        elements = pushes[dofs].any(axis=0)
        wider = dofs | reads[elements].any(axis=0)
        if np.array_equal(wider, dofs):
            break
        dofs = wider
    if dofs.all():
        return None
    return np.flatnonzero(dofs), np.flatnonzero(elements)


def reached_road(road: tuple, elements: np.ndarray, R: int) -> tuple:
    """The road's arrays for the kernel (:func:`.compiled._edge_arrays` after the inputs'
    part and whether each half step has one, both kept whole) of the ``elements`` alone."""
    both = np.concatenate([elements, R + elements])
    off, active, split_of, first, h, rights, middles, lefts, jumps, kicks, start, no_pull = road

    def part(a, cols):
        return np.ascontiguousarray(a[..., cols])

    return (
        part(off, both), active, split_of, first, h, part(rights, both), part(middles, both),
        part(lefts, both), part(jumps, elements), kicks, part(start, elements), no_pull[elements],
    )  # fmt: skip


def renumbered(wanted: np.ndarray, n: int, dofs: np.ndarray) -> np.ndarray:
    """Rows ``wanted`` of ``[q; q'; q'']`` (3n) as rows of the kept ``dofs``' own."""
    kind, dof = np.divmod(wanted, n)
    return kind * dofs.size + np.searchsorted(dofs, dof)
