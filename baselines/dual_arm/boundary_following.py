"""Minimum start delay of robot 2 by following the collision region's boundary.

Paper section III (steps 1-3 and the two remarks after Fig. 4), on a lazy
:class:`~motiongym.baselines.dual_arm.collision_map.CollisionMap`:

1. Walk along robot 2's TLVST curve (moves "0": +s1 and "1": +s2), checking
   each cell.
2. On meeting a collision cell, follow the region's boundary with the region
   on the left of the direction of travel (left-hand rule over the moves
   "0" +s1, "1" +s2, "2" -s1, "3" -s2 of Fig. 4: try left, straight, right,
   back), starting with the region straight ahead turned to the left.
3. A boundary point whose leaving move is "0" or "1" is a departure
   candidate: from it the TLVST curve is followed again, shifted so that it
   passes through the point. A candidate already taken before is not taken
   again (the paper's guard against cycling). The last candidate found is
   the departure point dp; the delay is ``TD = k2 - k1`` samples (Fig. 9:
   ``(66 - 31) * 0.02 s``), ``k2`` the column of dp and ``k1`` the column
   where the undelayed curve reaches dp's level.
4. The delayed curve is checked from its start to dp; if it meets another
   collision region, steps 2-3 are repeated from there, until it is clear.

Our reading where the text is open, each documented and tested:
* "From a candidate, proceed along the TLVST curve": the curve is shifted to
  pass through the candidate *and leave it by the walk's own move* ("0" or
  "1"), with the smallest such shift: for "1" the candidate is the last cell
  of the curve's run on its level, ``D = s1 - b(s2)``; for "0" the one before
  it, ``D = s1 - b(s2) + 1`` (``a(s2)``, ``b(s2)``: first and last column of
  the undelayed curve on level ``s2``; the paper's ``k2 - k1`` with ``k1`` the
  undelayed column at dp). Cells of the shifted curve behind the candidate
  are what step 4 re-checks. The other reading, the curve *entering* the
  candidate's level there (``D = s1 - a(s2)``, ``shift="enter"``), stops at
  the first free curve along a region's lower edge, one or more samples late
  where robot 2 climbs slower than one level per sample: on the 200 sampled
  pairs of ``motiongym reproduce dual-arm``, "move" equals the exhaustive
  minimum on 200, "enter" on 168.
* Outside the map (``s1 < 0``, ``s2 < 0``, ``s2 > N_l``) is blocked; right of
  ``N1`` robot 1 rests, so columns repeat; right of ``N1 + N2`` (a delay past
  sequential operation) is blocked.
* The method fails (returns ``delay=None``) when the start cell collides,
  when the boundary walk returns to a state it has been in without a new
  candidate since (it would cycle for ever), or after ``max_rounds`` rounds
  of step 4. The paper says the time-delay method cannot solve every case.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from motiongym.baselines.dual_arm.collision_map import CollisionMap

MOVES = ((1, 0), (0, 1), (-1, 0), (0, -1))  # "0" +s1, "1" +s2, "2" -s1, "3" -s2


@dataclass
class BoundaryResult:
    """Outcome of :func:`boundary_following`.

    Attributes:
        delay: start delay of robot 2 in samples (None: the method failed).
        departure: dp as ``(s1, s2)`` (None if no region was met).
        evaluated: distinct map cells evaluated.
        trace: every move made, in order, as ``(s1, s2, mode)``: the cell left
            and how, "t" along the TLVST curve, "b" along a region's boundary
            (the last entry is the curve's end).
        candidates: the departure candidates in the order they were taken.
        rounds: how many times step 4 found another region.
        reason: why it failed ("" on success).
    """

    delay: int | None
    departure: tuple[int, int] | None
    evaluated: int
    trace: list[tuple[int, int, str]] = field(default_factory=list)
    candidates: list[tuple[int, int]] = field(default_factory=list)
    rounds: int = 0
    reason: str = ""


def _blocked(cmap: CollisionMap, s1: int, s2: int) -> bool:
    if s1 > cmap.n1 + cmap.n2 + 1:
        return True
    return cmap.blocked(s1, s2)


def _boundary_move(cmap: CollisionMap, s1: int, s2: int, heading: int) -> int | None:
    """Left-hand rule: the first free of left, straight, right, back."""
    for turn in (1, 0, 3, 2):
        h = (heading + turn) % 4
        dx, dy = MOVES[h]
        if not _blocked(cmap, s1 + dx, s2 + dy):
            return h
    return None


def _search(
    cmap: CollisionMap,
    start: tuple[int, int],
    delay: int,
    taken: set[tuple[int, int]],
    result: BoundaryResult,
    max_steps: int,
    shift: str = "move",
) -> tuple[int, tuple[int, int] | None] | None:
    """Steps 1-3 from ``start`` on the curve delayed by ``delay``, to the curve's end.

    Returns ``(delay, dp)`` of the last candidate (dp None if none was taken), or
    None on failure (``result.reason`` says why).
    """
    s1, s2 = start
    mode, heading = "t", 0
    departure: tuple[int, int] | None = None
    seen: dict[tuple[int, int, int], int] = {}
    for _ in range(max_steps):
        if mode == "t":
            move = cmap.next_on_curve(s1, s2, delay)
            if move is None:
                result.trace.append((s1, s2, "t"))
                return delay, departure
            dx, dy = MOVES[move]
            if not _blocked(cmap, s1 + dx, s2 + dy):
                result.trace.append((s1, s2, "t"))
                s1, s2 = s1 + dx, s2 + dy
                continue
            mode, heading = "b", (move + 3) % 4  # region ahead: turn right, keep it left
        move = _boundary_move(cmap, s1, s2, heading)
        if move is None:
            result.reason = f"enclosed at {(s1, s2)}"
            return None
        if move in (0, 1) and (s1, s2) not in taken:
            shifted = cmap.departure_delay(s1, s2, move if shift == "move" else None)
            if shifted is not None:  # else left of the undelayed curve: no delay fits
                taken.add((s1, s2))
                result.candidates.append((s1, s2))
                departure, delay, mode = (s1, s2), shifted, "t"
                continue
        state = (s1, s2, move)
        if seen.get(state) == len(taken):
            result.reason = f"boundary walk cycles at {(s1, s2)} with no new candidate"
            return None
        seen[state] = len(taken)
        result.trace.append((s1, s2, "b"))
        heading = move
        s1, s2 = s1 + MOVES[move][0], s2 + MOVES[move][1]
    result.reason = f"no end after {max_steps} steps"
    return None


def boundary_following(
    cmap: CollisionMap, max_rounds: int = 20, max_steps: int | None = None, shift: str = "move"
) -> BoundaryResult:
    """The paper's minimum-delay search; see the module docstring.

    Args:
        cmap: the (lazy) collision map; its ``evaluated`` counter is read before
            and after, so a fresh map gives the method's own count.
        max_rounds: repetitions of step 4 before giving up.
        max_steps: bound on walk steps per round (default: 8 x the map's cells).
        shift: how the TLVST curve is shifted through a candidate: "move" (our
            reading, default) or "enter" (the alternative reading; see above).
    Returns:
        :class:`BoundaryResult`; ``delay * dt`` is the paper's TD.
    """
    if shift not in ("move", "enter"):
        raise ValueError(f"unknown shift {shift!r}; choose 'move' or 'enter'")
    before = cmap.evaluated
    steps = max_steps or 8 * (cmap.n1 + cmap.n2 + 2) * (cmap.n_levels + 1)
    result = BoundaryResult(delay=None, departure=None, evaluated=0)
    if cmap.blocked(0, 0):
        result.reason = "the arms collide at their start configurations"
        result.evaluated = cmap.evaluated - before
        return result
    taken: set[tuple[int, int]] = set()
    start, delay, departure = (0, 0), 0, None
    for rounds in range(max_rounds + 1):
        found = _search(cmap, start, delay, taken, result, steps, shift)
        if found is None:
            break
        delay, dp = found
        departure = dp or departure
        # Step 4: the delayed curve from its start to dp must be clear.
        s1s, s2s = cmap.curve(delay)
        stop = len(s1s)
        if departure is not None:
            at = (s1s == departure[0]) & (s2s == departure[1])
            stop = int(at.argmax()) if at.any() else len(s1s)
        clash = next((i for i in range(stop) if _blocked(cmap, int(s1s[i]), int(s2s[i]))), None)
        if clash is None:
            result.delay, result.departure, result.rounds = delay, departure, rounds
            break
        if clash == 0:
            result.reason = "the delayed curve collides at its start"
            break
        start = (int(s1s[clash - 1]), int(s2s[clash - 1]))
    else:
        result.reason = f"another region after {max_rounds} rounds"
    result.evaluated = cmap.evaluated - before
    return result


def plan_paper_case() -> BoundaryResult:
    """Boundary following on the paper case, from a fresh map (a benchmark hook).

    Building the lazy map is part of planning: its cells are evaluated on
    demand by the search itself.
    """
    from motiongym.envs.dual_arm.task import paper_case

    return boundary_following(CollisionMap.from_tasks(*paper_case(), n_levels=100))
