"""The section 5.2 reproduction command and the retune benchmark's figures."""

import json
import subprocess
import sys

from wirefish_analysis import bench_retune


def test_reproduce_paper_meets_the_paper_rmse_and_writes_the_figures(tmp_path):
    result = subprocess.run([sys.executable, '-m', 'wirefish_analysis.reproduce_paper',
                             '--out', str(tmp_path)], capture_output=True, text=True,
                            timeout=300)
    assert result.returncode == 0, result.stdout + result.stderr
    for name in ('fig6a.png', 'fig6b.png', 'fig7a.png', 'fig7bc.png'):
        assert (tmp_path / name).stat().st_size > 10_000, name
    summary = json.loads((tmp_path / 'summary.json').read_text())
    assert summary['loss'] < summary['table1_loss'] < summary['table1_loss_headward_wave']
    assert 'RMSE theta1 / theta2' in result.stdout


def test_bench_retune_reports_the_figures_the_bench_report_reads():
    figures = bench_retune.run(repeats=1, baseline=False)
    assert {'wall_s_median', 'loss', 'iterations', 'how'} <= set(figures)
    assert figures['wall_s_median'] > 0.0 and figures['loss'] > 0.0
