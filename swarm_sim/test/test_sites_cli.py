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
    assert main(['validate', str(broken)]) == 2
    assert 'broken.lay:6:1: the enclosure is open' in capsys.readouterr().err


def test_render_draws_a_png(tmp_path: Path) -> None:
    png = tmp_path / 'office.png'
    assert main(['render', str(CONFIG_DIR / 'office_plan.lay'), '-o', str(png)]) == 0
    assert png.read_bytes().startswith(PNG_MAGIC)


def test_unknown_file_types_and_missing_files_fail_cleanly(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(['validate', str(tmp_path / 'site.txt')]) == 2
    assert "unknown site file type '.txt'" in capsys.readouterr().err
    assert main(['validate', str(tmp_path / 'missing.yaml')]) == 2
    assert 'missing.yaml' in capsys.readouterr().err


def test_a_bad_departure_argument_is_a_one_line_usage_error(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    argv = ['import-lay', 'x.lay', '-o', str(tmp_path / 'x.yaml'), '--departure', 'center']
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count('\n') == 1
    assert 'expected NAME=LINE,COLUMN' in err


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
    assert 'warning: the site has no rooms' in captured.err
    # Validation prints the warnings, then refuses the site: it has nothing to search.
    assert main(['validate', str(plan)]) == 2
    err = capsys.readouterr().err
    assert f'warning: {plan}:2:7:' in err
    assert err.endswith(
        f'site_tool: {plan}: the site has no rooms; a search needs at least one'
        ' (coverage would be 0/0)\n'
    )
    # The site file holds the void as solid already: nothing left to warn about.
    assert main(['validate', str(out)]) == 2
    err = capsys.readouterr().err
    assert 'warning' not in err
    assert err.count('\n') == 1


@pytest.mark.parametrize(
    ('argv', 'expected'),
    [
        (['import-lay', 'IN', '-o', 'out.txt'], '--output out.txt: expected a .yaml or .yml file'),
        (['import-lay', 'IN', '-o', 'plan.lay'], '--output plan.lay: expected a .yaml or .yml'),
        (['import-lay', 'IN', '-o', 'a.yaml', '--png', 'a.yaml'], '--png a.yaml: expected a .png'),
        (['import-lay', 'IN', '-o', 'a.yaml', '--name', ''], '--name must not be empty'),
        (['generate', '--seed', '1', '-o', 'g.yaml', '--lay', 'g.yaml'], '--lay g.yaml: expected'),
        (['generate', '--seed', '1', '-o', 'g.yaml', '--png', 'g2.yaml'], '--png g2.yaml: exp'),
        (['render', 'IN', '-o', 'x.yaml'], '--output x.yaml: expected a .png, .svg or .pdf'),
        (
            [
                'generate',
                '--seed',
                '1',
                '--width-cells',
                '0',
                '--height-cells',
                '40',
                '-o',
                'g.yaml',
            ],
            '--width-cells must be a positive integer, got 0',
        ),
        (['generate', '--seed', '1', '--rooms', '-2', '-o', 'g.yaml'], '--rooms must be a pos'),
    ],
)
def test_bad_outputs_and_options_are_refused_before_anything_is_written(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    argv: list[str],
    expected: str,
) -> None:
    plan = tmp_path / 'plan.lay'
    plan.write_bytes((CONFIG_DIR / 'office_plan.lay').read_bytes())
    monkeypatch.chdir(tmp_path)
    assert main([str(plan) if item == 'IN' else item for item in argv]) == 2
    err = capsys.readouterr().err
    assert err.count('\n') == 1
    assert expected in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ['plan.lay']
    assert plan.read_bytes() == (CONFIG_DIR / 'office_plan.lay').read_bytes()


def test_an_output_that_is_the_input_is_refused_even_through_a_link(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    plan = tmp_path / 'plan.yaml'  # a layout under a site file's name
    original = (CONFIG_DIR / 'office_plan.lay').read_bytes()
    plan.write_bytes(original)
    link = tmp_path / 'link.yaml'
    link.symlink_to(plan)
    for out in (plan, link):
        assert main(['import-lay', str(plan), '-o', str(out)]) == 2
        assert 'is the input file; it is never overwritten' in capsys.readouterr().err
    assert plan.read_bytes() == original


def test_validate_refuses_oversized_and_recursive_site_files_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    text = (CONFIG_DIR / 'small_seed1.yaml').read_text()
    big = tmp_path / 'big.yaml'
    big.write_text(text.replace('width_m: 15.733333', 'width_m: 10000.0'))
    recursive = tmp_path / 'loop.yaml'
    recursive.write_text('a: &a [*a]\n')
    assert main(['validate', str(big)]) == 2
    assert 'big.yaml:6: bounds.width_m: 10000 m is larger than the 1000 m' in (
        capsys.readouterr().err
    )
    assert main(['validate', str(recursive)]) == 2
    err = capsys.readouterr().err
    assert 'loop.yaml:1: a[0]: an alias refers to the collection that contains it' in err
    assert err.count('\n') == 1
