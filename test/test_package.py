"""The repository root is a buildable ament_python package (colcon build into a temp base)."""

import ast
from importlib.machinery import EXTENSION_SUFFIXES
import os
from pathlib import Path
import shutil
import subprocess
import sys
from typing import Set
import xml.etree.ElementTree as ElementTree

import baseball_collision
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


IMPORT_TO_ROSDEP = {
    'numpy': 'python3-numpy', 'yaml': 'python3-yaml', 'matplotlib': 'python3-matplotlib',
    'tqdm': 'python3-tqdm', 'rosbags': 'python3-rosbags-pip', 'pytest': 'python3-pytest',
    'hypothesis': 'python3-hypothesis', 'threadpoolctl': 'python3-threadpoolctl',
    'apsw': 'python3-rosbags-pip',  # rosbags' SQLite driver, installed with it
}
"""Python modules whose rosdep key is not their own name."""

IMPORT_TO_PIP = {'numpy': 'numpy', 'yaml': 'PyYAML', 'rosbags': 'rosbags', 'tqdm': 'tqdm',
                 'matplotlib': 'matplotlib', 'threadpoolctl': 'threadpoolctl', 'apsw': 'apsw'}
"""Modules that come from PyPI (not from ROS), by their distribution name."""


def _third_party_imports(*roots: Path) -> Set[str]:
    """Return the top-level modules imported under ``roots`` that are neither stdlib nor ours."""
    found = set()
    for root in roots:
        for path in ([root] if root.is_file() else sorted(root.rglob('*.py'))):
            for node in ast.walk(ast.parse(path.read_text())):
                if isinstance(node, ast.Import):
                    found.update(alias.name.split('.')[0] for alias in node.names)
                elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                    found.add(node.module.split('.')[0])
    local = {'baseball_collision', 'support', 'conftest'}
    return {name for name in found if name not in sys.stdlib_module_names and name not in local}


def _depends(tag: str) -> Set[str]:
    root = ElementTree.parse(REPO_ROOT / 'package.xml').getroot()
    return {element.text for element in root.findall(tag)}


def test_package_xml_declares_exactly_what_the_package_imports() -> None:
    """Every import of the package and launch file is an exec_depend, and nothing else is."""
    imports = _third_party_imports(REPO_ROOT / 'baseball_collision', REPO_ROOT / 'launch')
    declared = {IMPORT_TO_ROSDEP.get(name, name) for name in imports}
    assert declared == _depends('exec_depend')


def test_package_xml_declares_what_the_tests_import() -> None:
    """Every import of the tests is a test_depend or an exec_depend."""
    imports = _third_party_imports(REPO_ROOT / 'test')
    declared = {IMPORT_TO_ROSDEP.get(name, name) for name in imports}
    assert declared - _depends('exec_depend') - _depends('test_depend') == set()


def test_setup_py_requires_what_comes_from_pypi() -> None:
    """install_requires (and the plots extra) name every PyPI module the package imports."""
    imports = _third_party_imports(REPO_ROOT / 'baseball_collision')
    pypi = {IMPORT_TO_PIP[name] for name in imports if name in IMPORT_TO_PIP}
    setup = ast.parse((REPO_ROOT / 'setup.py').read_text())
    call = next(node for node in ast.walk(setup) if isinstance(node, ast.Call)
                and getattr(node.func, 'id', '') == 'setup')
    keywords = {k.arg: ast.literal_eval(k.value) for k in call.keywords
                if k.arg in ('install_requires', 'extras_require', 'version')}
    required = set(keywords['install_requires'])
    required |= {name for extra in keywords['extras_require'].values() for name in extra}
    assert pypi <= required, pypi - required
    pinned = {line.split('==')[0].split('[')[0].lower() for line in
              (REPO_ROOT / 'requirements.txt').read_text().splitlines()
              if line and not line.startswith('#')}
    assert {name.lower() for name in pypi} <= pinned


def test_one_version_everywhere() -> None:
    """package.xml, setup.py and baseball_collision.__version__ name the same version."""
    xml_version = ElementTree.parse(REPO_ROOT / 'package.xml').getroot().findtext('version')
    setup = (REPO_ROOT / 'setup.py').read_text()
    assert f"version='{xml_version}'" in setup
    assert baseball_collision.__version__ == xml_version
    assert (REPO_ROOT / 'LICENSE').read_text().lstrip().startswith('Apache License')
    root = ElementTree.parse(REPO_ROOT / 'package.xml').getroot()
    assert root.findtext('license') == 'Apache-2.0'


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
    _installed_kernel_is_used(prefix, env, tmp_path)
    # the installed command line runs from the install (through ``entry_points``)
    site = next((prefix / 'lib').glob('python3*/site-packages'))
    completed = subprocess.run(
        [sys.executable, str(prefix / 'lib' / 'baseball_collision' / 'baseball-collision'),
         '--help'], cwd=tmp_path, capture_output=True, text=True, timeout=60,
        env=dict(env, PYTHONPATH=str(site)))
    assert completed.returncode == 0, completed.stderr
    assert 'analyze' in completed.stdout


def _installed_kernel_is_used(prefix: Path, env: dict, cwd: Path) -> None:
    """Check the build compiled the time-of-impact kernel and the installed package uses it."""
    site = next((prefix / 'lib').glob('python3*/site-packages'))
    toi = site / 'baseball_collision' / 'core' / 'toi'
    kernels = [toi / f'_kernel{suffix}' for suffix in EXTENSION_SUFFIXES
               if (toi / f'_kernel{suffix}').is_file()]
    assert kernels, sorted(p.name for p in toi.iterdir())
    probe = ('import baseball_collision.core.toi as toi\n'
             'print(toi._kernel.__file__)\n'
             'print(toi.time_of_impact([2, 0, 0], [0, 0, 0], [1, 0, 0], [1, 0, 0], [0, 0, 0], '
             '[0, 0, 0], 0.05, 0.05, 1.0).time)')
    completed = subprocess.run([sys.executable, '-c', probe], cwd=cwd, capture_output=True,
                               text=True, timeout=60, env=dict(env, PYTHONPATH=str(site)))
    assert completed.returncode == 0, completed.stderr
    used, contact = completed.stdout.split()
    assert Path(used).resolve() == kernels[0].resolve()
    assert float(contact) == pytest.approx(0.45, abs=1e-12)
