"""The fish's Ijspeert CPG (eq 1): the cpg node, its gaits and the gait library it reads."""

from wirefish_common.startup_signals import hold_stop_signals_for

hold_stop_signals_for('cpg_node')
