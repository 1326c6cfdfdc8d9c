# SPDX-License-Identifier: Apache-2.0
"""The 1-fish rows of `make bench`: the median of alternated runs, every run's figure kept."""

from wirefish_bench import bench, bench_graph


def test_each_executor_gets_its_median_run_and_the_runs_alternate(monkeypatch):
    figures = iter([60.0, 30.0, 70.0, 25.0, 50.0, 40.0])  # classic, events, classic, ...
    order = []

    def fleet(fish, duration_s, domain_id, single_process, executor):
        order.append(executor)
        return {'executor': executor, 'fish': fish, 'single_process': single_process,
                'onboard_cpu_percent_per_fish': next(figures)}

    monkeypatch.setattr(bench_graph, 'fleet', fleet)
    medians = {r['executor']: r for r in bench.one_fish(3, 1.0, 0, False)}
    assert order == ['classic', 'events'] * 3
    assert medians['classic']['onboard_cpu_percent_per_fish'] == 60.0
    assert medians['classic']['onboard_cpu_percent_runs'] == [60.0, 70.0, 50.0]
    assert medians['events']['onboard_cpu_percent_per_fish'] == 30.0
    assert medians['events']['onboard_cpu_percent_runs'] == [30.0, 25.0, 40.0]
