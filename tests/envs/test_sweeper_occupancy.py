"""The sweeper's grid model, maps and procedural generator: known cases and brute force."""

from __future__ import annotations

import re

import numpy as np
import pytest

from motiongym.envs.sweeper import generator, maps, occupancy


def brute_box_sum(image: np.ndarray, w: int) -> np.ndarray:
    h, wd = image.shape
    out = np.zeros((h, wd), np.int64)
    for r in range(h):
        for c in range(wd):
            out[r, c] = image[r : r + w, c : c + w].sum()
    return out


@pytest.mark.parametrize("w", [1, 2, 3, 4])
def test_box_sum_matches_brute_force(w: int) -> None:
    image = np.random.default_rng(w).integers(0, 3, size=(9, 13))
    np.testing.assert_array_equal(occupancy.box_sum(image, w), brute_box_sum(image, w))


def test_config_free_and_footprint_union_known_room() -> None:
    grid = generator.empty_room(6, 7)  # 4 x 5 free floor
    free = occupancy.config_free(grid, 2)
    assert free.sum() == 3 * 4  # anchors (1..3, 1..4)
    assert free[1, 1] and free[3, 4] and not free[4, 4] and not free[0, 1]
    cover = occupancy.footprint_union(free, 2)
    np.testing.assert_array_equal(cover, ~grid)


def test_footprint_union_matches_brute_force() -> None:
    configs = np.random.default_rng(0).random((10, 12)) < 0.1
    w = 3
    brute = np.zeros_like(configs)
    for r, c in np.argwhere(configs):
        brute[r : r + w, c : c + w] = True
    np.testing.assert_array_equal(occupancy.footprint_union(configs, w), brute)


def test_reachable_cells_exclude_gaps_narrower_than_robot() -> None:
    grid = generator.empty_room(10, 15)
    grid[:, 7] = True
    grid[4, 7] = False  # a one-cell door: a 3-wide robot cannot pass
    reach = occupancy.reachable_cells(grid, 3, (1, 1))
    assert reach[1:9, 1:7].all() and not reach[:, 8:].any()
    assert not reach[4, 7]  # the door cell itself cannot be swept


def test_entering_mask() -> None:
    east = occupancy.entering_mask(0, 1, 3)
    np.testing.assert_array_equal(east, np.array([[0, 0, 1]] * 3, bool))
    assert occupancy.entering_mask(1, 1, 3).sum() == 5
    assert occupancy.entering_mask(0, 0, 3).sum() == 0


def test_smartdfs_bound_empty_room() -> None:
    reach = np.ones((12, 18), bool)  # 12 x 18 floor: 4 x 6 blocks of 3 x 3
    bound = occupancy.smartdfs_bound(reach, 3)
    assert (bound.cells, bound.edges, bound.holes) == (24, 20, 0)
    assert bound.steps == 24 + 10 - 3  # SmartDFS: C + E/2 - 3
    assert bound.ratio == bound.simple_ratio == pytest.approx(3 * 31 / (216 / 3))


def test_robot_scale_cells_split_where_a_thin_wall_crosses_a_block() -> None:
    reach = np.ones((3, 9), bool)
    reach[:, 4] = False  # a wall one cell thick through the middle block
    # blocks 0 | 1a 1b | 2: the middle block holds a cell each side of the wall,
    # each the neighbour of the block beside it only
    assert occupancy.robot_scale_cells(reach, 3) == (4, 16 - 4)
    reach[1, 4] = True  # a door: the two halves touch inside the block, one cell
    assert occupancy.robot_scale_cells(reach, 3) == (3, 12 - 4)


def test_obstacle_count_and_the_bound_around_obstacles() -> None:
    reach = np.ones((12, 12), bool)
    reach[0:2, 5:8] = False  # against the frame: part of the outside, not an obstacle
    assert occupancy.obstacle_count(reach) == 0
    reach[5:7, 5:7] = False  # an island the robot can go round
    reach[9, 2] = False  # and a pillar
    assert occupancy.obstacle_count(reach) == 2
    bound = occupancy.smartdfs_bound(reach, 3)
    # every block stays one piece and touches its neighbours: C = 16, E = 16 (the frame)
    assert (bound.cells, bound.edges, bound.holes, bound.area) == (16, 16, 2, 133)
    assert bound.steps == bound.cells + bound.edges / 2 + 3 * 2 - 2  # C + E/2 + 3H - 2
    assert bound.steps == 28 and bound.simple_steps == 21
    assert bound.ratio == pytest.approx(9 * 28 / 133)
    assert bound.simple_ratio < bound.ratio


def test_bfs_distance_and_descend() -> None:
    free = np.ones((5, 5), bool)
    free[1:4, 2] = False
    dist = occupancy.bfs_distance(free, (2, 0))
    assert dist[2, 4] == 8  # around the wall: up 2, across 4, down 2
    path = occupancy.descend(dist, (2, 4))
    assert len(path) == 8 and path[-1] == (2, 4)
    assert all(free[p] for p in path)


def test_shipped_maps_sizes_and_closed() -> None:
    shapes = {"room": (30, 40), "apartment": (40, 60), "maze": (48, 48)}
    for name, shape in shapes.items():
        grid = maps.shipped_map(name)
        assert grid.shape == shape
        assert occupancy.is_closed(grid)
        assert occupancy.config_free(grid, 3).any()


def test_map_errors(tmp_path) -> None:
    with pytest.raises(maps.MapError, match="unknown map 'kitchen'"):
        maps.shipped_map("kitchen")
    with pytest.raises(ValueError, match="map_file must be an existing"):
        maps.load_map_file(tmp_path / "none.txt")
    (tmp_path / "open.txt").write_text("####\n#...\n####\n")
    with pytest.raises(maps.MapError, match="not closed"):
        maps.load_map_file(tmp_path / "open.txt")
    (tmp_path / "full.txt").write_text("###\n###\n")
    with pytest.raises(maps.MapError, match="no free cell"):
        maps.load_map_file(tmp_path / "full.txt")
    (tmp_path / "bad.txt").write_text("###\n#x#\n###\n")
    with pytest.raises(maps.MapError, match="line 2, column 2: character 'x'"):
        maps.load_map_file(tmp_path / "bad.txt")
    (tmp_path / "m.bmp").write_text("")
    with pytest.raises(maps.MapError, match="unknown format"):
        maps.load_map_file(tmp_path / "m.bmp")


def test_png_and_text_round_trip(tmp_path) -> None:
    from PIL import Image

    grid = maps.shipped_map("room")
    Image.fromarray(np.where(grid, 0, 255).astype(np.uint8)).save(tmp_path / "room.png")
    np.testing.assert_array_equal(maps.load_map_file(tmp_path / "room.png"), grid)
    (tmp_path / "room.txt").write_text(maps.to_text(grid))
    np.testing.assert_array_equal(maps.load_map_file(tmp_path / "room.txt"), grid)


@pytest.mark.parametrize("angle", [0, 30, 45, 90])
def test_rotate_map_stays_closed(angle: float) -> None:
    turned = maps.rotate_map(maps.shipped_map("maze"), angle)
    assert occupancy.is_closed(turned)
    free_before = (~maps.shipped_map("maze")).sum()
    assert abs((~turned).sum() - free_before) < 0.1 * free_before


def test_generator_fifty_maps_closed_with_room_for_robot() -> None:
    rng = np.random.default_rng(0)
    kinds = set()
    for _ in range(50):
        kind = generator.KINDS[int(rng.integers(3))]
        kinds.add(kind)
        grid = generator.random_map(rng, 3, kind)
        assert occupancy.is_closed(grid)
        assert occupancy.config_free(grid, 3).sum() > 20
        assert max(grid.shape) <= 64
    assert kinds == set(generator.KINDS)
    with pytest.raises(ValueError, match="unknown map kind"):
        generator.random_map(rng, 3, "castle")


def test_smartdfs_bound_blocks_anchored_at_the_start() -> None:
    reach = np.ones((12, 18), bool)
    assert occupancy.smartdfs_bound(reach, 3, (3, 6)) == occupancy.smartdfs_bound(reach, 3)
    bound = occupancy.smartdfs_bound(reach, 3, (1, 1))  # blocks straddle the floor's edges
    assert (bound.cells, bound.edges) == (35, 24)


@pytest.mark.parametrize(
    ("text", "w", "message"),
    [
        ("#####\n#...#\n#.o.#\n#####\n", 1, "line 3, column 3: character 'o'"),
        ("#####\n#...#\n#..\t#\n#####\n", 1, "line 3, column 4: character '\\t'"),
        ("#####\n#...#\n#..#\n#####\n", 1, "line 3, column 5: ragged rows, this line has 4"),
        ("#####\n#...##\n#####\n", 1, "line 2, column 6: ragged rows, this line has 6"),
        ("#####\n#...#\n\n#####\n", 1, "line 3, column 1: ragged rows"),
        ("\n#####\n#...#\n#####\n", 1, "line 2, column 1: ragged rows"),
        ("#####\n#....\n#####\n", 1, "not closed: line 2, column 5 is a free cell on the border"),
        ("#.###\n#...#\n#####\n", 1, "not closed: line 1, column 2"),
        (
            "######\n#..#.#\n#..###\n######\n",
            3,
            "no free place for a robot of width 3: the widest free square is 2 x 2 cells, "
            "at line 2, column 2",
        ),
        ("#####\n#####\n", 1, "has no free cell"),
    ],
)
def test_bad_map_files_get_one_line_naming_line_and_column(tmp_path, text, w, message) -> None:
    path = tmp_path / "m.txt"
    path.write_text(text)
    with pytest.raises(maps.MapError, match=re.escape(message)) as caught:
        maps.load_map_file(path, w)
    assert "\n" not in str(caught.value)
    assert str(path) in str(caught.value)


def test_blank_lines_after_a_map_are_ignored_and_the_env_checks_the_robot_width(tmp_path) -> None:
    path = tmp_path / "m.txt"
    path.write_text("#####\n#...#\n#...#\n#...#\n#####\n\n\n")
    assert maps.load_map_file(path).shape == (5, 5)
    from motiongym.envs.sweeper.env import SweeperEnv

    SweeperEnv(map_file=str(path), robot_width=3).reset(seed=0)
    with pytest.raises(
        maps.MapError, match="widest free square is 3 x 3 cells, at line 2, column 2"
    ):
        SweeperEnv(map_file=str(path), robot_width=4)
