"""The same OA-Bug mission on both physics backends: comparable coverage, no robot in a wall;
the spawner's --physics and --render options (pybullet tests skipped where it is missing)."""

import numpy as np
import pytest
from swarm_experiments.oabug_batch import run_spawn_batch
from swarm_experiments.spawn import SpawnSettings
from swarm_sim.engine import EngineConfig
from swarm_sim.geometry import point_segment_distance
from swarm_sim.site_geometry import geometry_from_site
from swarm_sim.site_loading import load_site

# Robot radius plus half the wall thickness: a robot centre closer than this to a wall's
# centre line would be inside the wall (1 mm allowed for pybullet's contact tolerance).
CONTACT_M = 0.1 + 0.0125 - 1e-3
# Rooms the two backends may differ by after 60 s (4 robots, Small site, 30 rooms): 10 %.
ROOM_TOLERANCE = 3


@pytest.mark.slow
def test_one_mission_on_both_backends_covers_alike_and_keeps_out_of_the_walls():
    pytest.importorskip('pybullet', reason='pybullet is not installed (Python > 3.11?)')
    site = load_site('small', seed=0)
    walls = geometry_from_site(site).walls
    results = {}
    for physics in ('numpy', 'pybullet'):
        # 180 actions of 0.1 m at 0.3 m/s: 60 s of sim time.
        settings = SpawnSettings(
            site='small',
            site_seed=0,
            variant='gas_sound',
            robots=4,
            actions=180,
            engine=EngineConfig(physics=physics),
        )
        results[physics] = run_spawn_batch(settings).mission
    for physics, mission in results.items():
        assert mission.sim_time_s == pytest.approx(60.0)
        xy = mission.trajectories[:, :, :2].reshape(-1, 2)
        assert point_segment_distance(xy, walls).min() > CONTACT_M, physics
        assert mission.distance_travelled_m.sum() > 4 * 0.8 * 0.3 * 60.0, physics
    covered = {physics: m.rooms_covered for physics, m in results.items()}
    assert covered['numpy'] >= 8  # the mission does explore
    assert abs(covered['numpy'] - covered['pybullet']) <= ROOM_TOLERANCE, covered
    # Two different worlds: the paths part ways (contacts and rays are not bit-identical).
    assert not np.array_equal(results['numpy'].trajectories, results['pybullet'].trajectories)


def test_spawner_refuses_rendering_without_pybullet_physics_in_one_line(capsys):
    from swarm_experiments.spawn import main

    assert main(['--render', 'gui', '--no-plots']) == 2
    err = capsys.readouterr().err
    assert 'needs the pybullet physics' in err
    assert err.count('\n') == 1


def test_spawner_refuses_a_malformed_render_option(capsys):
    from swarm_experiments.spawn import main

    assert main(['--physics', 'pybullet', '--render', 'frames', '--no-plots']) == 2
    assert "--render takes 'gui' or 'frames DIR'" in capsys.readouterr().err


@pytest.mark.slow
def test_spawner_runs_on_pybullet_and_writes_frames(tmp_path, capsys):
    pytest.importorskip('pybullet', reason='pybullet is not installed (Python > 3.11?)')
    from swarm_experiments.spawn import main

    frames = tmp_path / 'frames'
    argv = ['--robots', '2', '--actions', '15', '--physics', 'pybullet', '--quiet']
    assert main([*argv, '--render', 'frames', str(frames), '--no-plots']) == 0
    out = capsys.readouterr().out
    assert 'stopped by budget after 5.0 s sim' in out
    assert len(list(frames.glob('frame_*.png'))) == 11  # 2 Hz over 5 s, and t = 0
    assert (frames / 'run.gif').stat().st_size > 0
