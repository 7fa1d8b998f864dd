"""ament_python set-up for baseball_collision (colcon build, or pip install from the root)."""

from glob import glob

from setuptools import Extension, find_packages, setup

package_name = 'baseball_collision'

# The exact time-of-impact kernel, in C (core/toi/_kernel.c): built by `pip install`, `pip
# install -e .` and `colcon build` with the C compiler Python was built with. Standard C99 and
# the CPython API; with numpy's headers where the build sees numpy (make setup, colcon build),
# it reads numpy rows from the array struct (KERNEL_NUMPY_ROWS: 6 rows read in ~60 ns instead of
# ~640 ns through the buffer protocol); an isolated build without numpy reads them through the
# buffer protocol, with the same results. -ffp-contract=off: no fused multiply-add (gcc's
# default on arm64), so results are the same to the last bit on every machine. -O3 over -O2:
# about 7 % less CPU per contact-heavy batch row (gcc 12, x86-64), the same results to the bit.
try:
    import numpy
except ImportError:  # an isolated build: no numpy headers
    numpy = None
kernel = Extension(
    package_name + '.core.toi._kernel', sources=['baseball_collision/core/toi/_kernel.c'],
    include_dirs=[numpy.get_include()] if numpy else [],
    define_macros=[('KERNEL_NUMPY_ROWS', '1')] if numpy else [],
    extra_compile_args=['-std=c99', '-O3', '-ffp-contract=off', '-fno-math-errno'])

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test', 'test.*', 'benchmarks']),
    ext_modules=[kernel],
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
        # the node's parameters, and views of its topics: RViz config, Foxglove layout
        ('share/' + package_name + '/config',
         glob('config/*.yaml') + glob('config/*.rviz') + glob('config/*.json')),
        ('share/' + package_name + '/launch', glob('launch/*.launch.py')),
        ('share/' + package_name + '/schema', glob('schema/*.json')),
        ('share/' + package_name + '/bags', glob('bags/*.*')),
        ('share/' + package_name + '/bags/pitches_120hz_sqlite3',
         glob('bags/pitches_120hz_sqlite3/*')),
    ],
    # what the package imports from PyPI (package.xml declares the same for rosdep; the ROS 2
    # packages come from ROS itself); test/test_package.py checks both against the imports
    install_requires=['setuptools', 'apsw', 'numpy', 'PyYAML', 'rosbags', 'threadpoolctl', 'tqdm'],
    extras_require={'plots': ['matplotlib']},  # only `analyze --plot` needs it
    zip_safe=False,  # a compiled extension
    maintainer='baseball_collision maintainers',
    maintainer_email='maintainers@users.noreply.h-seed-561ec417.example',
    description='Exact bat-ball time of impact from tracked frames: ROS 2 node and bag analysis.',
    license='Apache-2.0',
    tests_require=['pytest'],
    entry_points={
        'console_scripts': [
            'impact_node = baseball_collision.entry_points:impact_node',
            'baseball-collision = baseball_collision.entry_points:command_line',
            # the same CLI under a name ros2 run completes like the node's
            'baseball_collision = baseball_collision.entry_points:command_line',
        ],
    },
)
