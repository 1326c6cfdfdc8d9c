"""The fish's TF tree (REP-105): odom, base_link, imu_link, tail_base and the tail's frames."""

from wirefish_common.startup_signals import hold_stop_signals_for

hold_stop_signals_for('tf_node')
