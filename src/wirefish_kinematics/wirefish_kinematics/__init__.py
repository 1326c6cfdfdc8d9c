"""Wire-coupled arc kinematics of the elastic tail and the Lighthill swimming-speed model."""

from wirefish_common.startup_signals import hold_stop_signals_for

hold_stop_signals_for('kinematics_node')
