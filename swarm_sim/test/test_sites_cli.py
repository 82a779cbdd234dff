"""site_tool: generate, import, validate and render through main(), as a user would."""

from __future__ import annotations

from pathlib import Path

import pytest
from swarm_sim.sites.cli import main
from swarm_sim.sites.layout import read_layout
from swarm_sim.sites.site_file import load_site

CONFIG_DIR = Path(__file__).resolve().parents[1] / 'config' / 'sites'
PNG_MAGIC = b'\x89PNG\r\n\x1a\n'


def test_generate_writes_the_site_its_layout_and_a_picture(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out, lay, png = tmp_path / 's.yaml', tmp_path / 's.lay', tmp_path / 's.png'
    code = main(
        [
            'generate',
            '--config',
            'small',
            '--seed',
            '3',
            '-o',
            str(out),
            '--lay',
            str(lay),
            '--png',
            str(png),
        ]
    )
    assert code == 0
    site = load_site(out)
    assert site.name == 'small-seed3'
    assert len(site.rooms) == 30
    assert read_layout(lay).shape == (30, 60)
    assert png.read_bytes().startswith(PNG_MAGIC)
    assert '30 rooms' in capsys.readouterr().out


def test_generate_accepts_free_sizes(tmp_path: Path) -> None:
    out = tmp_path / 'c.yaml'
    args = [
        'generate',
        '--width-cells',
        '44',
        '--height-cells',
        '36',
        '--rooms',
        '20',
        '--victims',
        '2',
    ]
    assert main([*args, '--seed', '5', '-o', str(out)]) == 0
    site = load_site(out)
    assert len(site.rooms) == 20
    assert sum(room.has_victim for room in site.rooms) == 2
    assert site.width_m == pytest.approx(43 * 4 / 15)


def test_import_lay_says_how_many_rooms_it_found(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / 'office.yaml'
    code = main(
        [
            'import-lay',
            str(CONFIG_DIR / 'office_plan.lay'),
            '-o',
            str(out),
            '--departure-name',
            'edge',
        ]
    )
    assert code == 0
    assert 'unlabelled layout, found 10 rooms' in capsys.readouterr().out
    assert set(load_site(out).departure_points) == {'edge'}


def test_import_lay_takes_explicit_departure_points(tmp_path: Path) -> None:
    out = tmp_path / 'office.yaml'
    lay = str(CONFIG_DIR / 'office_plan.lay')
    assert (
        main(
            [
                'import-lay',
                lay,
                '-o',
                str(out),
                '--departure',
                'center=7,20',
                '--departure',
                'edge=16,19.5',
            ]
        )
        == 0
    )
    assert set(load_site(out).departure_points) == {'center', 'edge'}


def test_validate_accepts_the_example_files_and_rejects_a_broken_one(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    for name in ('small_seed1.yaml', 'small_seed1.lay', 'office_plan.lay'):
        assert main(['validate', str(CONFIG_DIR / name)]) == 0
    broken = tmp_path / 'broken.lay'
    lines = (CONFIG_DIR / 'office_plan.lay').read_text().splitlines()
    lines[5] = ' ' + lines[5][1:]
    broken.write_text('\n'.join(lines) + '\n')
    assert main(['validate', str(broken)]) == 1
    assert 'broken.lay:6:1: the enclosure is open' in capsys.readouterr().err


def test_render_draws_a_png(tmp_path: Path) -> None:
    png = tmp_path / 'office.png'
    assert main(['render', str(CONFIG_DIR / 'office_plan.lay'), '-o', str(png)]) == 0
    assert png.read_bytes().startswith(PNG_MAGIC)


def test_unknown_file_types_and_missing_files_fail_cleanly(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(['validate', str(tmp_path / 'site.txt')]) == 1
    assert "unknown site file type '.txt'" in capsys.readouterr().err
    assert main(['validate', str(tmp_path / 'missing.yaml')]) == 1
    assert 'missing.yaml' in capsys.readouterr().err


def test_a_bad_departure_argument_is_an_argparse_error(tmp_path: Path) -> None:
    with pytest.raises(SystemExit):
        main(['import-lay', 'x.lay', '-o', str(tmp_path / 'x.yaml'), '--departure', 'center'])


def test_import_and_validate_log_the_sites_warnings_on_stderr(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    plan = tmp_path / 'boxes.lay'
    plan.write_text(
        '%%%%%%%%%%%%\n%    %     %\n%    %%%%%%%\n%  D       %\n%          %\n%%%%%%%%%%%%\n'
    )
    out = tmp_path / 'boxes.yaml'
    assert main(['import-lay', str(plan), '-o', str(out)]) == 0
    captured = capsys.readouterr()
    assert 'found 0 rooms and 0 doors, 1 sealed voids read as solid' in captured.out
    assert f'warning: {plan}:2:7: an enclosed area with no door' in captured.err
    assert main(['validate', str(plan)]) == 0
    assert f'warning: {plan}:2:7:' in capsys.readouterr().err
    # The site file holds the void as solid already: nothing left to warn about.
    assert main(['validate', str(out)]) == 0
    assert 'warning' not in capsys.readouterr().err
