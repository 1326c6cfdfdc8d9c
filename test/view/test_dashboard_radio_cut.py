# SPDX-License-Identifier: Apache-2.0
"""
The dashboard through a radio cut, in a real browser (headless chromium, Selenium).

The page is that of a running `wirefish up --sim --view --radio wired --drive-mode gait`: the
virtual fish runs the gait behind the radio model. A cut (``cut SECONDS`` written to the run's
radio-control) loses everything on the air both ways, so the bridge hears nothing and its last
status bits no longer tell the fish's state (behind the cut the fish coasts, then rests). The
claims: during the cut the badge says the link is lost, with how long there has been no
telemetry and what a gait-mode fish does meanwhile, never the stale gait; after it the badge
shows the board's gait again.
"""

import re
import time

import pytest

pytestmark = [pytest.mark.ros, pytest.mark.loads_machine]

GRAPH_OPTIONS = ('--radio', 'wired', '--drive-mode', 'gait')
CUT_S = 5.0
SILENT = re.compile(r'no telemetry for (\d+\.\d) s: link lost \(the fish coasts, then rests\)')
BADGE = ("[document.getElementById('v-link-badge').dataset.state, "
         "document.getElementById('v-link-badge').textContent]")


def test_a_radio_cut_shows_the_link_lost_then_the_gait_again(dashboard, view_graph):
    assert dashboard.wait("window.wirefish.board && window.wirefish.board.state === 'gait'",
                          60.0), dashboard.live('window.wirefish.board')
    runs = sorted(view_graph.graph.out_dir.glob('run_*'))
    assert runs, f'no run directory in {view_graph.graph.out_dir}'
    (runs[-1] / 'radio-control').write_text(f'cut {CUT_S}\n')
    cut_at = time.monotonic()
    shown: list[tuple[float, str, str]] = []   # (s after the cut was asked, state, words)
    while time.monotonic() < cut_at + CUT_S + 10.0:
        state, words = dashboard.live(BADGE)
        if not shown or shown[-1][1:] != (state, words):
            shown.append((time.monotonic() - cut_at, state, words))
        if state == 'gait' and any(s == 'silent' for _, s, _ in shown):
            break
        time.sleep(0.1)
    print('\n'.join(f'{t:5.2f} s {state}: {words}' for t, state, words in shown))
    silent = [(t, words) for t, state, words in shown if state == 'silent']
    assert silent, shown
    assert all(SILENT.fullmatch(words) for _, words in silent), silent
    ages = [float(SILENT.fullmatch(words).group(1)) for _, words in silent]
    assert max(ages) > 1.0 and max(ages) <= CUT_S + 2.0, ages
    assert shown[-1][1] == 'gait', shown   # the board's gait again after the cut
    first_silent = next(i for i, (_, state, _) in enumerate(shown) if state == 'silent')
    assert all(state in ('silent', 'coasting', 'resting', 'gait')
               for _, state, _ in shown[first_silent:]), shown
