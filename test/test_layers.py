"""
The layers of the package: what each sub-package may import (the tree in the README).

core/ is pure Python + numpy and imports nothing above it; rclpy and the ROS message packages
are imported only under ros/, rosbags only under bags/; nothing in the package imports the
tools but the tools themselves. Checked on the source (every import statement, also the ones
inside functions), so a lazy import cannot hide.
"""

import ast
from pathlib import Path
from typing import Iterator, Tuple

from support import REPO_ROOT

PACKAGE = REPO_ROOT / 'baseball_collision'
ROS = {'rclpy', 'builtin_interfaces', 'diagnostic_msgs', 'geometry_msgs', 'nav_msgs',
       'rcl_interfaces', 'rosgraph_msgs', 'std_msgs', 'std_srvs', 'visualization_msgs',
       'launch', 'launch_ros'}
OUTSIDE_CORE = ROS | {'rosbags', 'matplotlib', 'tqdm', 'yaml', 'ament_index_python'}
LAYERS = ('core', 'ros', 'bags', 'tools')
ALLOWED = {  # layer -> the package's layers it may import
    'core': {'core'},
    'bags': {'core', 'bags'},
    'ros': {'core', 'bags', 'ros'},
    'tools': {'core', 'bags', 'ros', 'tools'},
}


def _imports() -> Iterator[Tuple[Path, str]]:
    """Yield (module path, absolute imported module) for every import in the package."""
    for path in sorted(PACKAGE.rglob('*.py')):
        package = path.relative_to(REPO_ROOT).with_suffix('').parts[:-1]
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                for alias in node.names:
                    yield path, alias.name
            elif isinstance(node, ast.ImportFrom):
                if node.level:
                    base = package[:len(package) - node.level + 1]
                    yield path, '.'.join(base + ((node.module,) if node.module else ()))
                else:
                    yield path, node.module or ''


def _layer(module: str) -> str:
    parts = module.split('.')
    return parts[1] if parts[0] == 'baseball_collision' and len(parts) > 1 else ''


def test_every_layer_imports_only_what_it_may() -> None:
    """No import crosses a layer upwards, and third-party stacks stay in their layer."""
    found = set()
    for path, module in _imports():
        where = path.relative_to(PACKAGE)
        layer = where.parts[0] if len(where.parts) > 1 else ''
        top = module.split('.')[0]
        if layer == 'core' and top in OUTSIDE_CORE:
            found.add((str(where), top))
        if top in ROS and layer != 'ros':
            found.add((str(where), top))
        if top == 'rosbags' and layer != 'bags':
            found.add((str(where), top))
        target = _layer(module)
        if layer in ALLOWED and target in LAYERS and target not in ALLOWED[layer]:
            found.add((str(where), module))
    assert found == set()


def test_the_checker_sees_relative_imports() -> None:
    """The core's relative imports resolve to the package (the check above is not vacuous)."""
    modules = {module for path, module in _imports() if 'core' in path.parts}
    assert 'baseball_collision.core.geometry' in modules
    assert 'baseball_collision.errors' in modules
