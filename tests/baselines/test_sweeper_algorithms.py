"""The sweeper paper's algorithms on their own: quadtree transfer, PSA pieces, CWA scan."""

from __future__ import annotations

import numpy as np
import pytest

from motiongym.baselines.sweeper import cwa, psa, quadtree
from motiongym.envs.sweeper import generator, maps, occupancy


def test_quadtree_leaves_tile_the_free_cells_exactly() -> None:
    free = occupancy.config_free(maps.shipped_map("apartment"), 3)
    leaves, label = quadtree.decompose(free)
    covered = np.zeros_like(free)
    for r, c, s in leaves:
        assert not covered[r : r + s, c : c + s].any()  # no overlap
        covered[r : r + s, c : c + s] = True
        assert s & (s - 1) == 0  # power-of-two squares
    np.testing.assert_array_equal(covered, free)
    np.testing.assert_array_equal(label >= 0, free)
    assert len(leaves) < free.sum() / 2  # the decomposition merges big free squares


@pytest.mark.parametrize("name", ["room", "apartment", "maze"])
def test_quadtree_path_valid_complete_and_near_shortest(name: str) -> None:
    free = occupancy.config_free(maps.shipped_map(name), 3)
    cells = np.argwhere(free)
    rng = np.random.default_rng(1)
    total_q = total_bfs = 0
    for _ in range(30):
        a = tuple(int(v) for v in cells[rng.integers(len(cells))])
        b = tuple(int(v) for v in cells[rng.integers(len(cells))])
        dist = occupancy.bfs_distance(free, a)
        path = quadtree.plan(free, a, b)
        if dist[b] < 0:
            assert path is None
            continue
        assert path is not None and (path[-1] == b or a == b)
        for p, q in zip([a, *path[:-1]], path, strict=True):
            assert abs(p[0] - q[0]) + abs(p[1] - q[1]) == 1 and free[q]
        total_q += len(path)
        total_bfs += dist[b]
    assert total_q <= 1.1 * total_bfs


def test_best_path_is_shortest_and_sweeps_the_leftover_strip() -> None:
    grid = generator.empty_room(12, 12)
    free = occupancy.config_free(grid, 3)
    todo = np.zeros(grid.shape, bool)
    todo[1, 8:11] = True  # a leftover strip along the north wall, to the east
    gains = psa.entering_gains(todo, 3)

    def swept_on_the_way(path: list[tuple[int, int]]) -> int:
        moves = zip([(1, 1), *path[:-1]], path, strict=True)
        k = {(0, 1): 0, (-1, 0): 1, (0, -1): 2, (1, 0): 3}
        return sum(gains[k[(b[0] - a[0], b[1] - a[1])]][b] for a, b in moves)

    best = quadtree.bfs_plan(free, (1, 1), (8, 8), gains)  # over all free configurations
    plain = quadtree.plan(free, (1, 1), (8, 8))
    assert len(best) == len(plain) == 14  # 7 + 7 moves: as short as any
    assert best[6] == (1, 8)  # east first, along the strip, then south
    assert swept_on_the_way(best) == 3 and swept_on_the_way(plain) == 0
    assert quadtree.plan(free, (1, 1), (1, 1), gains) == []
    # the quadtree's route keeps to its chain of squares: the strip lies outside it
    leaves, label = quadtree.decompose(free)
    chain = quadtree.leaf_chain(leaves, label, (1, 1), (8, 8))
    inside = quadtree.channel(leaves, chain, free.shape)
    routed = quadtree.plan(free, (1, 1), (8, 8), gains)
    assert len(routed) == 14 and all(inside[p] for p in routed)
    assert swept_on_the_way(routed) == 0


@pytest.mark.parametrize("name", ["apartment", "maze"])
def test_quadtree_route_stays_in_its_chain_and_near_shortest(name: str) -> None:
    """With gains the path keeps to the chain's squares; against the BFS ablation it is at
    most 10 % longer in total over 30 random pairs (measured: see the assertion's numbers)."""
    free = occupancy.config_free(maps.shipped_map(name), 3)
    cells = np.argwhere(free)
    rng = np.random.default_rng(2)
    gains = np.zeros((4, *free.shape), np.int64)
    leaves, label = quadtree.decompose(free)
    total_q = total_bfs = 0
    for _ in range(30):
        a = tuple(int(v) for v in cells[rng.integers(len(cells))])
        b = tuple(int(v) for v in cells[rng.integers(len(cells))])
        chain = quadtree.leaf_chain(leaves, label, a, b)
        if chain is None:
            assert quadtree.plan(free, a, b, gains) is None
            continue
        inside = quadtree.channel(leaves, chain, free.shape)
        path = quadtree.plan(free, a, b, gains)
        assert all(inside[p] for p in path) and (a == b or path[-1] == b)
        total_q += len(path)
        total_bfs += len(quadtree.bfs_plan(free, a, b, gains))
    assert total_bfs <= total_q <= 1.1 * total_bfs


def test_entering_gains_count_the_cells_a_move_sweeps() -> None:
    todo = np.zeros((6, 6), bool)
    todo[2, 1:4] = True
    gains = psa.entering_gains(todo, 3)
    assert gains[3, 0, 1] == 3  # moving south into (0, 1): row 2 enters, 3 cells
    assert gains[0, 2, 1] == 1  # moving east into (2, 1): column 3 enters, 1 cell
    assert gains[1, 2, 1] == 3 and gains[2, 2, 1] == 1


def test_quadtree_no_path_between_separate_rooms() -> None:
    grid = generator.empty_room(10, 21)
    grid[:, 10] = True
    free = occupancy.config_free(grid, 3)
    assert quadtree.plan(free, (1, 1), (1, 12)) is None


def test_side_segments_one_width_beside_the_lane() -> None:
    left, right = psa.side_segments((10, 5), (10, 15), 0, 3)  # a lane heading east
    assert left == psa.Segment((7, 5), 0, 11, 1)  # north of it, pointing away north
    assert right == psa.Segment((13, 5), 0, 11, 3)
    rows, cols = psa.segment_configs(right)
    assert rows.tolist() == [13] * 11 and cols.tolist() == list(range(5, 16))


def test_behind_segment_in_line_behind_the_lane_start() -> None:
    seg = psa.behind_segment((6, 56), 3, 9, 0)  # a lane starting at (6, 56) heading south
    assert seg == psa.Segment((5, 56), 1, 9, 0)  # from the cell behind, pointing north
    rows, cols = psa.segment_configs(seg)
    assert rows.tolist() == list(range(5, -4, -1)) and cols.tolist() == [56] * 9


def test_first_target_skips_swept_and_takes_nearer_end() -> None:
    seg = psa.Segment((0, 0), 0, 10, 3)
    cfree = np.ones((3, 12), bool)
    todo = np.zeros((3, 12), bool)
    todo[0, 3:8] = True  # configurations 3..7 along the segment still cover unswept cells
    assert psa.first_target(seg, (0, 0), cfree, todo) == ((0, 3), 0)
    dist = np.abs(np.arange(12) - 11)[None, :].repeat(3, 0)  # robot at the east end
    assert psa.first_target(seg, (0, 0), cfree, todo, dist) == ((0, 7), 2)
    todo[:] = False
    assert psa.first_target(seg, (0, 0), cfree, todo) is None  # the paper's skip


def test_lane_open_and_stack_is_lifo() -> None:
    occ = np.zeros((3, 3), np.int8)
    assert psa.lane_open(occ, np.array([True, False, True]))
    assert not psa.lane_open(occ, np.array([True, True, True]))  # nothing new ahead
    occ[1, 2] = 1
    assert not psa.lane_open(occ, np.array([False, False, False]))  # an obstacle ahead
    stack = psa.PsaStack()
    a, b = psa.Segment((0, 0), 0, 1, 1), psa.Segment((5, 5), 2, 3, 3)
    stack.push(a)
    stack.push(b)
    assert stack.pop() == (b, 0) and stack.pop() == (a, 0) and len(stack) == 0


def test_stack_groups_entries_by_the_run_that_pushed_them() -> None:
    stack = psa.PsaStack()
    segs = [psa.Segment((k, 0), 0, 1, 1) for k in range(5)]
    for seg, run in zip(segs, (0, 0, 1, 1, 1), strict=True):
        stack.push(seg, run)
    assert stack.top_run() == [2, 3, 4]  # the latest run's entries, bottom to top
    assert stack.pop(3) == (segs[3], 1)  # any of them may be taken
    stack.pop()
    stack.pop()
    assert stack.top_run() == [0, 1]  # then the run before, LIFO


def test_sweep_cost_counts_lanes_and_shifts() -> None:
    # a 20-cell corridor 7 cells wide, w = 3: along it 3 lanes of 17 moves and
    # 4 moves of shifts; across it 7 lanes of 4 moves and 17 moves of shifts
    assert psa.sweep_cost(20, 7, 3) == 3 * 17 + 4
    assert psa.sweep_cost(7, 20, 3) == 7 * 4 + 17
    assert psa.sweep_cost(3, 3, 3) == 0  # one configuration sweeps it


def test_restart_heading_turns_lanes_across_a_corridor_only() -> None:
    # popped at the west end of an east-west corridor 7 cells wide, 20 long:
    # stretches E 17, N 0, W 0, S 4 configurations (cells 20 x 7)
    stretch = (17, 0, 0, 4)
    # a segment heading east (lanes along the corridor): turned across it,
    # heading south (the longer way on that axis), shifting east
    assert psa.restart_heading(stretch, 0, 3, 3) == (3, 0)
    # a segment already across the corridor keeps its heading and side
    assert psa.restart_heading(stretch, 3, 0, 3) == (3, 0)
    # a square region keeps the segment's axis
    assert psa.restart_heading((6, 0, 0, 6), 0, 3, 3) == (0, 3)


def test_stretches_count_todo_configurations_in_a_row() -> None:
    todo = np.zeros((6, 8), bool)
    todo[2, 1:7] = True
    todo[0:5, 3] = True
    assert psa.stretches(todo, (2, 3)) == (3, 2, 2, 2)  # E, N, W, S


def test_cwa_scan_order_top_right_to_bottom_left() -> None:
    targets = np.zeros((8, 8), bool)
    targets[1, 1] = targets[1, 6] = targets[6, 3] = True  # three separate leftovers
    groups = cwa.scan_groups(targets)
    assert [seed for seed, _ in groups] == [(1, 6), (1, 1), (6, 3)]
    assert all(len(cells) == 1 for _, cells in groups)


def test_cwa_groups_leftovers_by_obstacle_contour() -> None:
    obstacle = generator.empty_room(10, 10)
    obstacle[4:6, 4:6] = True  # a pillar
    targets = np.zeros_like(obstacle)
    targets[1, 1] = targets[8, 8] = True  # corners of the outer wall: one contour
    targets[3, 4] = targets[6, 5] = True  # both sides of the pillar: another
    groups = cwa.scan_groups(targets, obstacle, reach=1)
    assert len(groups) == 2
    sizes = sorted(len(cells) for _, cells in groups)
    assert sizes == [2, 2]
    assert groups[0][0] == (1, 1)  # the outer wall's first cell in scan order


def test_cwa_leftovers_and_nearest_cover() -> None:
    grid = generator.empty_room(7, 9)
    occ = grid.astype(np.int8)
    swept = np.zeros_like(grid)
    swept[1:4, 1:8] = True  # one lane swept: rows 4-5 remain
    free = occupancy.config_free(grid, 3)
    reach = occupancy.reachable_configs(free, (1, 1))
    left = cwa.leftovers(occ, swept, reach, 3)
    assert left.sum() == 2 * 7 and left[4:6, 1:8].all()
    dist = occupancy.bfs_distance(free, (1, 1))
    assert cwa.nearest_cover(dist, np.argwhere(left), 3) == (2, 1)  # one step south


def test_toward_lane_moves_a_blocked_side_segment_back() -> None:
    seg = psa.Segment((13, 5), 0, 11, 3)  # south of a lane at row 10
    assert psa.toward_lane(seg, 0) == seg
    assert psa.toward_lane(seg, 2) == psa.Segment((11, 5), 0, 11, 3)
    # a one-row strip under the lane, then a wall: reachable only two rows back
    cfree = np.zeros((20, 20), bool)
    cfree[10:12, :] = True
    todo = np.ones((20, 20), bool)
    assert psa.first_target(seg, (0, 0), cfree, todo) is None
    assert psa.first_target(psa.toward_lane(seg, 2), (0, 0), cfree, todo) == ((11, 5), 0)
