# SPDX-License-Identifier: Apache-2.0
"""
`wirefish bag reindex|info BAG`: repair and inspect bags, as `ros2 bag reindex` / `ros2 bag info`.

``reindex`` makes a bag left by a killed recorder readable: its unfinished MCAP file is rebuilt
from the chunks that were flushed before the kill, and metadata.yaml is written.
``info`` prints what metadata.yaml says, after checking that its files and counts are the ones
the files' summaries give.
"""

import argparse
import enum
from pathlib import Path
import sys

from wirefish_bag.bag_storage import (IncompleteFile, METADATA_FILE, read_file_info,
                                      rosbag2_metadata, storage_files)
from wirefish_bag.reindex import reindex
from wirefish_common.input_checks import bag_directory_problem
import yaml

REINDEX_HINT = ' (a killed recording? `wirefish bag reindex BAG` repairs it)'


class BagAction(enum.StrEnum):
    """The actions of `wirefish bag`, as `ros2 bag` names them."""

    REINDEX = 'reindex'
    INFO = 'info'


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the sub-subcommands of `wirefish bag`."""
    actions = parser.add_subparsers(dest='action', required=True, metavar='ACTION')
    for name, help_text in ((BagAction.REINDEX, 'rebuild unfinished MCAP files and metadata.yaml'),
                            (BagAction.INFO, 'files, duration and message counts of a bag')):
        action = actions.add_parser(name.value, help=help_text, description=help_text)
        action.add_argument('bag', type=Path, help='rosbag2 directory')


def describe(metadata: dict) -> str:
    """Return a `ros2 bag info`-like text of a metadata.yaml content."""
    info = metadata['rosbag2_bagfile_information']
    lines = [f'Files:             {", ".join(info["relative_file_paths"])}',
             f'Duration:          {info["duration"]["nanoseconds"] * 1e-9:.3f}s',
             f'Start:             {info["starting_time"]["nanoseconds_since_epoch"]} ns',
             f'Messages:          {info["message_count"]}',
             'Topic information:']
    for entry in info['topics_with_message_count']:
        topic = entry['topic_metadata']
        lines.append(f'  Topic: {topic["name"]} | Type: {topic["type"]} | '
                     f'Count: {entry["message_count"]} | Serialization Format: '
                     f'{topic["serialization_format"]}')
    return '\n'.join(lines)


def _counts(metadata: dict) -> tuple[list[str], dict[str, int]]:
    """Return the files and the messages per topic that a metadata.yaml content lists."""
    info = metadata['rosbag2_bagfile_information']
    return info['relative_file_paths'], {e['topic_metadata']['name']: e['message_count']
                                         for e in info['topics_with_message_count']}


def run(args: argparse.Namespace) -> int:
    """Run `wirefish bag ...`; return the process exit code."""
    problem = bag_directory_problem(args.bag)
    if problem is not None:
        print(f'wirefish bag {args.action}: {problem}', file=sys.stderr)
        return 2
    try:
        if args.action == BagAction.REINDEX:
            for r in reindex(args.bag):
                print(f'{r.name}: rebuilt from {r.chunks} intact chunks ({r.messages} messages);'
                      f' left out {r.damaged_chunks} damaged chunks, {r.orphan_messages} '
                      f'messages without their channel and {r.dropped_tail_bytes} trailing bytes')
            print(f'wrote {args.bag / METADATA_FILE}')
        metadata = rosbag2_metadata([read_file_info(p) for p in storage_files(args.bag)])
        written = yaml.safe_load((args.bag / METADATA_FILE).read_text())
        _counts(written)
    except (OSError, IncompleteFile, KeyError, TypeError) as error:
        print(f'wirefish bag {args.action}: {error}{REINDEX_HINT}', file=sys.stderr)
        return 1
    if _counts(written) != _counts(metadata):
        print(f'wirefish bag {args.action}: {METADATA_FILE} counts other files or messages '
              f'than the files hold{REINDEX_HINT}', file=sys.stderr)
        return 1
    print(describe(written))
    return 0
