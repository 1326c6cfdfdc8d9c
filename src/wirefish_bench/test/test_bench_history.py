# SPDX-License-Identifier: Apache-2.0
"""A whole `make bench` rewrites BENCHMARKS.md's tables and keeps its History section as it was."""

from wirefish_bench.bench_report import kept_history, render_markdown

RESULTS = {'machine': {'cpu': 'cpu', 'cores': 2, 'python': '3.11', 'numpy': '2', 'kernel': 'k',
                       'date': '-'}}
HISTORY = '## History\n\n### A dated entry\n\nA figure of then.\n'


def test_the_history_of_the_previous_file_is_kept_after_the_new_table():
    previous = render_markdown(RESULTS, HISTORY).replace('| figure |', '| an old figure |')
    text = render_markdown(RESULTS, kept_history(previous))
    assert text.endswith('\n' + HISTORY)
    assert text.count('## History') == 1 and '| figure |' in text


def test_a_file_without_a_history_keeps_none():
    assert kept_history(render_markdown(RESULTS)) == ''
    assert kept_history('# Benchmarks\n\nsee ## History below\n') == ''
