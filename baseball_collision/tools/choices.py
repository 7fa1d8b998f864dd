"""
What ``baseball-collision simulate`` accepts: kinds, swing families, bat layouts, limits.

Plain constants with no imports: the command line builds ``simulate``'s options from them at
every start (``analyze`` too), and :mod:`.sim` and :mod:`.recording` import them from here, so
starting the command line imports neither the simulator nor the recording writer.
"""

KINDS = ('barrel', 'end_cap', 'handle', 'graze', 'miss_over', 'miss_under')
"""Scenario kinds ``sim.make_scenario`` builds (``sim.Scenario`` also accepts ``'custom'``)."""

FAMILIES = ('plane', 'tilted', 'jerky', 'lefty', 'braking', 'rebound')
"""The swing families ``sim.make_scenario`` draws (``sim.families``), today's fixed plane first."""

NOISE_ON = ('both', 'ball', 'bat')
"""The bodies whose samples get the tracking noise (``sim.sample``'s ``noise_on``)."""

BAT_CHOICES = ('both', 'pose', 'points')
"""How the bat is written: pose and points, the pose only, or knob and tip points only."""

MAX_RATE_HZ = 100_000.0
"""Fastest tracker simulated (Hz): 100 kHz, far above any rig, keeps a pitch under 40k samples."""

MAX_SEED = 2 ** 64 - 1
"""Largest random seed (seeds are 0 ... 2^64 - 1)."""
