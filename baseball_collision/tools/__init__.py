"""
Command-line tools: analyze, simulate, replay, the demo, reports and plots.

No rclpy and no ROS message package here (the demo's ROS side is ``ros.listener``); rosbags
only through ``bags``. Modules: ``analyze`` (the one detector loop over a bag), ``events`` (one
table by event type), ``report`` (table, JSON, CSV), ``plots`` and ``summary_plot``
(matplotlib, lazily), ``outbag`` (``--out-bag`` for Foxglove), ``truth`` (truth files and the
one matching rule), ``accuracy`` (against the simulator's truth),
``outputs`` (all-or-nothing outputs), ``parameters`` (node parameter files), ``recording``
(``simulate``), ``demo``, ``cli``, and ``sim`` (the simulator).
"""
