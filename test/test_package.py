"""The repository root is a buildable ament_python package (colcon build into a temp base)."""

import os
from pathlib import Path
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ElementTree

import pytest
from support import REPO_ROOT


def test_package_xml_declares_the_runtime_dependencies() -> None:
    """package.xml is format 3, ament_python, and names what the node imports."""
    root = ElementTree.parse(REPO_ROOT / 'package.xml').getroot()
    assert root.get('format') == '3'
    assert root.findtext('name') == 'baseball_collision'
    assert root.find('export/build_type').text == 'ament_python'
    exec_depends = {e.text for e in root.findall('exec_depend')}
    assert {'rclpy', 'geometry_msgs', 'std_msgs', 'visualization_msgs', 'diagnostic_msgs',
            'std_srvs', 'python3-numpy'} <= exec_depends
    test_depends = {e.text for e in root.findall('test_depend')}
    assert {'ament_flake8', 'ament_pep257', 'python3-pytest'} <= test_depends


def _colcon() -> str:
    found = shutil.which('colcon') or str(Path(sys.executable).parent / 'colcon')
    if not Path(found).exists():
        pytest.skip('colcon is not installed')
    return found


def test_colcon_build_installs_executables_and_data(tmp_path: Path) -> None:
    """A colcon build from the root installs the console scripts, package.xml and configs."""
    colcon = _colcon()
    env = dict(os.environ)
    env.pop('RMW_IMPLEMENTATION', None)
    completed = subprocess.run(
        [colcon, '--log-base', str(tmp_path / 'log'), 'build',
         '--build-base', str(tmp_path / 'build'), '--install-base', str(tmp_path / 'install')],
        cwd=REPO_ROOT, env=env, capture_output=True, text=True, timeout=300)
    assert completed.returncode == 0, completed.stdout + completed.stderr
    prefix = tmp_path / 'install' / 'baseball_collision'
    for executable in ('impact_node', 'baseball-collision'):
        assert (prefix / 'lib' / 'baseball_collision' / executable).is_file()
    share = prefix / 'share' / 'baseball_collision'
    assert (share / 'package.xml').is_file()
    assert (prefix / 'share' / 'ament_index' / 'resource_index' / 'packages'
            / 'baseball_collision').is_file()
    for config in (REPO_ROOT / 'config').glob('*.yaml'):
        assert (share / 'config' / config.name).is_file()
    for bag in (REPO_ROOT / 'bags').rglob('*'):  # the demo's recordings and their truth
        if bag.is_file():
            assert (share / bag.relative_to(REPO_ROOT)).is_file(), bag
    assert not (REPO_ROOT / 'build').exists() and not (REPO_ROOT / 'install').exists()
