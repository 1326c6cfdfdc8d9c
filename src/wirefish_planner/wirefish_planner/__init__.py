"""Drive the fish: cmd_vel to gait (inverse speed model) and IMU heading control."""

from wirefish_common.startup_signals import hold_stop_signals_for

hold_stop_signals_for('planner_node')
