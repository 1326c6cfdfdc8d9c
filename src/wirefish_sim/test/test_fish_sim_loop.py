# SPDX-License-Identifier: Apache-2.0
"""fish_sim's loop behind real time: it integrates at most MAX_STEP_S a pass, drops the rest."""

import pytest
from wirefish_sim.fish_sim import loop_step, MAX_STEP_S


@pytest.mark.parametrize('elapsed, step, dropped', [
    (0.004, 0.004, 0.0), (MAX_STEP_S, MAX_STEP_S, 0.0), (3.0, MAX_STEP_S, 3.0 - MAX_STEP_S),
    (-0.001, 0.0, 0.0)])
def test_a_pass_integrates_at_most_its_bound_and_drops_the_backlog(elapsed, step, dropped):
    assert loop_step(elapsed) == pytest.approx((step, dropped))
