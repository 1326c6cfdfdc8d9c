# SPDX-License-Identifier: Apache-2.0
"""
Benchmark: one retune of the section 5.2 case, ours against the obvious implementation.

Ours: ``wirefish_tuner.tuning.fit_gait`` with the tuner's defaults (40 particles, at most 100
iterations, stall stop), closed-form steady state of eq 1, whole swarm per array operation.
Baseline ("the obvious way"): pyswarms' GlobalBestPSO with the same bounds, swarm size,
inertia and learning factors, run for the same number of iterations as ours took, whose
objective integrates eq 1 particle by particle (plain RK4 loop, 2 ms step, 3 s to settle,
``wirefish_tuner.reference_loss``) and scores the last cycle with the same loss definition.
Both final positions are then scored with the exact loss, so "equal or better final loss" is
judged on one ruler. pyswarms draws from NumPy's global RNG, so the baseline seeds it.

``python -m wirefish_bench.bench_retune`` prints the figures as JSON.

Gait library rows: ``library_answer`` times the same goal twice through a real
tuner_node process and its retune_gait action (the first fits, the rest come from the
library), client round trip and the tuner's own figure; ``gaits_build`` times
``wirefish gaits build`` on its default grid.
"""

from __future__ import annotations

import json
import logging
from pathlib import Path
import statistics
import sys
import time

import numpy as np
from wirefish_tuner.pso import PsoOptions
from wirefish_tuner.reference_loss import simulated_body_wave_loss
from wirefish_tuner.tuning import fit_gait
from wirefish_tuner.wave_loss import (body_wave_loss, PAPER_LOWER, PAPER_UPPER,
                                      swing_angle_rmse_deg, WaveFitProblem)

PAPER_RMSE_DEG = (1.7165, 1.2817)


def _ours(problem: WaveFitProblem, seed: int, options: PsoOptions) -> dict:
    stamps: list[float] = []
    start = time.perf_counter()
    fit = fit_gait(problem, np.random.default_rng(seed), options,
                   callback=lambda *_: stamps.append(time.perf_counter() - start))
    rmse = swing_angle_rmse_deg(fit.pso.position_history, problem)
    met = np.flatnonzero(np.all(rmse <= PAPER_RMSE_DEG, axis=1))
    return {'wall_s': fit.elapsed_s, 'loss': fit.loss, 'iterations': fit.iterations,
            'rmse_theta_deg': fit.rmse_theta_deg.tolist(),
            'wall_s_to_paper_rmse': stamps[met[0]] if met.size else None,
            'position': fit.pso.best_position}


def _baseline(problem: WaveFitProblem, seed: int, options: PsoOptions, iterations: int,
              settle_s: float, step_s: float) -> dict:
    import pyswarms

    logging.getLogger('pyswarms').setLevel(logging.WARNING)
    np.random.seed(seed)  # pyswarms only knows NumPy's global RNG

    def objective(swarm: np.ndarray) -> np.ndarray:
        return np.array([simulated_body_wave_loss(x, problem, settle_s=settle_s,
                                                  step_s=step_s) for x in swarm])

    optimizer = pyswarms.single.GlobalBestPSO(
        n_particles=options.swarm_size, dimensions=PAPER_LOWER.size,
        options={'c1': options.cognitive, 'c2': options.social, 'w': options.inertia},
        bounds=(PAPER_LOWER, PAPER_UPPER))
    start = time.perf_counter()
    own_cost, position = optimizer.optimize(objective, iters=iterations, verbose=False)
    wall = time.perf_counter() - start
    return {'wall_s': wall, 'own_loss': float(own_cost),
            'loss': float(body_wave_loss(np.asarray(position)[None], problem)[0]),
            'rmse_theta_deg': swing_angle_rmse_deg(np.asarray(position)[None],
                                                   problem)[0].tolist()}


def run(repeats: int = 5, seed: int = 0, baseline: bool = True,
        baseline_settle_s: float = 3.0, baseline_step_s: float = 2e-3) -> dict:
    """
    Time ``repeats`` retunes of the section 5.2 case and one baseline run; return the figures.

    Keys: wall_s_median, wall_s_runs, wall_s_to_paper_rmse_median, loss, rmse_theta_deg,
    iterations, baseline_wall_s, baseline_loss (exact loss of its best position),
    baseline_own_loss (its simulated objective), baseline_rmse_theta_deg, ratio, how.
    """
    problem = WaveFitProblem()
    options = PsoOptions()
    _ours(problem, seed, options)  # warm-up: imports, caches
    runs = [_ours(problem, seed, options) for _ in range(repeats)]
    first = runs[0]
    result = {
        'wall_s_median': statistics.median(r['wall_s'] for r in runs),
        'wall_s_runs': [r['wall_s'] for r in runs],
        'wall_s_to_paper_rmse_median': statistics.median(
            r['wall_s_to_paper_rmse'] for r in runs) if first['wall_s_to_paper_rmse'] else None,
        'loss': first['loss'], 'rmse_theta_deg': first['rmse_theta_deg'],
        'iterations': first['iterations'], 'swarm_size': options.swarm_size,
        'how': (f'section 5.2 wave, seed {seed}, {options.swarm_size} particles, '
                f'{first["iterations"]} iterations (max {options.max_iterations}, stall stop); '
                f'median of {repeats}; baseline: pyswarms GlobalBestPSO, same bounds/swarm/'
                f'weights/iterations, eq 1 integrated per particle (RK4 {baseline_step_s:g} s, '
                f'{baseline_settle_s:g} s settle); both scored with the exact loss'),
    }
    if baseline:
        base = _baseline(problem, seed, options, first['iterations'], baseline_settle_s,
                         baseline_step_s)
        result.update({'baseline_wall_s': base['wall_s'], 'baseline_loss': base['loss'],
                       'baseline_own_loss': base['own_loss'],
                       'baseline_rmse_theta_deg': base['rmse_theta_deg'],
                       'ratio': base['wall_s'] / result['wall_s_median'],
                       'loss_not_worse_than_baseline': first['loss'] <= base['loss']})
    return result


def tuner_executable() -> Path:
    """Return the installed tuner_node executable (`ros2 run wirefish_tuner tuner_node`)."""
    from ament_index_python.packages import get_package_prefix

    return Path(get_package_prefix('wirefish_tuner'), 'lib', 'wirefish_tuner', 'tuner_node')


def library_answer(repeats: int = 20, domain_id: int = 97) -> dict:
    """
    Return round-trip times (s) of a fitted goal and of ``repeats`` library answers.

    Keys: fit_round_trip_s, library_round_trip_s_median / _max (client: send_goal to result),
    library_tuner_s_median (the tuner's elapsed_s: look-up only), all_from_library, how.
    """
    import os
    import subprocess
    import tempfile

    import rclpy
    from rclpy.action import ActionClient
    from rclpy.context import Context
    from rclpy.executors import SingleThreadedExecutor
    from wirefish_msgs.action import RetuneGait

    tuner = str(tuner_executable())
    env = dict(os.environ, ROS_DOMAIN_ID=str(domain_id), ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    with tempfile.TemporaryDirectory() as scratch:
        library = Path(scratch) / 'gaits.yaml'
        process = subprocess.Popen([sys.executable, tuner, '--ros-args', '-r',
                                    '__ns:=/bench_retune', '-p', f'library_path:={library}'],
                                   env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        context = Context()
        rclpy.init(context=context, domain_id=domain_id)
        try:
            node = rclpy.create_node('bench_retune', namespace='/bench_retune', context=context)
            executor = SingleThreadedExecutor(context=context)
            executor.add_node(node)
            client = ActionClient(node, RetuneGait, 'retune_gait')
            deadline = time.monotonic() + 30.0
            while not client.wait_for_server(timeout_sec=1.0):
                if process.poll() is not None:  # say why, not only that nothing answered
                    raise RuntimeError(f'{tuner} exited with {process.returncode}')
                if time.monotonic() > deadline:
                    raise RuntimeError('no retune_gait action server within 30 s')

            def round_trip() -> tuple[float, RetuneGait.Result]:
                goal = RetuneGait.Goal()
                goal.wave.c1, goal.wave.c2, goal.wave.k, goal.wave.frequency_hz = (
                    0.15, 1.0, 8.0, 1.0)
                start = time.perf_counter()
                sent = client.send_goal_async(goal)
                executor.spin_until_future_complete(sent, timeout_sec=60.0)
                result = sent.result().get_result_async()
                executor.spin_until_future_complete(result, timeout_sec=120.0)
                return time.perf_counter() - start, result.result().result

            fit_s, first = round_trip()
            answers = [round_trip() for _ in range(repeats)]
        finally:
            rclpy.try_shutdown(context=context)
            process.terminate()
            process.wait(timeout=10)
    trips = [t for t, _ in answers]
    return {'fit_round_trip_s': fit_s, 'fit_iterations': first.iterations,
            'library_round_trip_s_median': statistics.median(trips),
            'library_round_trip_s_max': max(trips),
            'library_tuner_s_median': statistics.median(r.elapsed_s for _, r in answers),
            'all_from_library': all(r.from_library for _, r in answers),
            'how': (f'section 5.2 wave as a retune_gait action goal to a tuner_node process '
                    f'(fresh library): 1 fit, then {repeats} identical goals; client round '
                    'trip send_goal -> result; tuner figure = its elapsed_s')}


def gaits_build(workers: int | None = None) -> dict:
    """Return the wall time (s) of `wirefish gaits build` on its default grid."""
    import os
    import subprocess
    import tempfile

    with tempfile.TemporaryDirectory() as scratch:
        command = [sys.executable, '-m', 'wirefish_cli.cli', 'gaits', 'build', '--library',
                   str(Path(scratch) / 'gaits.yaml'), '--workers',
                   str(workers or os.cpu_count() or 1)]
        start = time.perf_counter()
        done = subprocess.run(command, capture_output=True, text=True, timeout=600)
        wall = time.perf_counter() - start
    stored = done.stdout.strip().splitlines()[-1] if done.stdout.strip() else done.stderr
    return {'wall_s': wall, 'returncode': done.returncode, 'summary': stored,
            'how': 'wirefish gaits build, default grid (5 frequencies x 5 scales of the '
                   'section 5.2 wave), all cores, fresh library'}


if __name__ == '__main__':
    json.dump(run(baseline='--no-baseline' not in sys.argv), sys.stdout, indent=2)
    print()
