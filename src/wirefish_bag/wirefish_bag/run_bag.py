# SPDX-License-Identifier: Apache-2.0
"""
The end of a recorded run (`wirefish up --duration`): repair, report, and the loss account.

The launcher is the last to see the run, so it closes the run's bag with these; they live
with the bag library, which a host that records installs (the fish records nothing).
"""

from pathlib import Path
import sys

from wirefish_bag.bag_storage import (IncompleteFile, read_file_info, recording_custom_data,
                                      storage_files)
from wirefish_bag.reindex import reindex
from wirefish_bag.sequence_gaps import loss_line


def close_run_bag(bag_path: Path, report_dir: Path | None) -> None:
    """
    Finish a run's bag: reindex an unfinished file, write the report, print the loss line.

    ``report_dir`` None: no report (a run that did not stop cleanly). The loss account is the
    last line either way.
    """
    finish_bag(bag_path)
    if report_dir is not None:
        from wirefish_bag.report import write_report
        write_report(bag_path, report_dir)
        print(f'bag: {bag_path}\nreport: {report_dir}')
    print(loss_line(recording_custom_data(bag_path)), flush=True)


def finish_bag(bag_path: Path) -> None:
    """
    Reindex the run's bag if a recorder left a file of it unfinished (no summary, no footer).

    A recorder that was killed, or stopped while its restart was still starting up (before
    its --resume reindexed the last file), leaves the bag unfinished: the launcher is the last
    to see the run, so it repairs the bag rather than leave `wirefish bag reindex` to the user.
    """
    def finished(path: Path) -> bool:
        try:
            read_file_info(path)
        except (IncompleteFile, OSError):
            return False
        return True

    files = storage_files(bag_path)
    whole = all(finished(path) for path in files) and (bag_path / 'metadata.yaml').exists()
    if not files or whole:
        return
    try:
        recoveries = reindex(bag_path)
    except (OSError, ValueError) as error:  # IncompleteFile is a ValueError
        print(f'wirefish up: the bag {bag_path} was left unfinished and could not be '
              f'reindexed: {error}; try `wirefish bag reindex {bag_path}`', file=sys.stderr)
        return
    print(f'wirefish up: the recorder left {bag_path} unfinished; reindexed it ('
          + ', '.join(f'{r.name}: {r.messages} messages' for r in recoveries) + ')',
          file=sys.stderr)
