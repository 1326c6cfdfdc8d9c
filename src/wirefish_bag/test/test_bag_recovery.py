# SPDX-License-Identifier: Apache-2.0
"""
Bags as the recorder writes them: finished ones read back whole, killed ones after a reindex.

Every bag is read with rosbags (an independent MCAP reader), never with our own decoder.
"""

from pathlib import Path

from mcap.reader import make_reader
import numpy as np
import pytest
from rosbags.highlevel import AnyReader
from wirefish_bag.bag_storage import (IncompleteFile, MAGIC, next_file_path, read_file_info,
                                      storage_files)
from wirefish_bag.recorder import open_bag_file
from wirefish_bag.reindex import reindex
from wirefish_bag.sequence_gaps import loss_line, recording_losses
from wirefish_cli import cli
import yaml

SEED = 20261201


def read_texts(bag_dir: Path, typestore) -> list[str]:
    with AnyReader([bag_dir], default_typestore=typestore) as reader:
        return [reader.deserialize(raw, connection.msgtype).data
                for connection, _, raw in reader.messages()]


def metadata(bag_dir: Path) -> dict:
    return yaml.safe_load((bag_dir / 'metadata.yaml').read_text())['rosbag2_bagfile_information']


def test_a_finished_bag_reads_back_every_message(finished_bag, typestore):
    assert read_texts(finished_bag.bag_dir, typestore) == finished_bag.texts


def test_metadata_is_what_rosbag2_jazzy_writes(finished_bag, offered_qos):
    info = metadata(finished_bag.bag_dir)
    assert (info['version'], info['storage_identifier']) == (9, 'mcap')
    assert info['relative_file_paths'] == ['bag_0.mcap']
    assert info['message_count'] == 120
    assert info['starting_time']['nanoseconds_since_epoch'] == 1_000_000_000
    assert info['duration']['nanoseconds'] == 119 * 1_000_000
    assert [f['message_count'] for f in info['files']] == [120]
    topics = {t['topic_metadata']['name']: t for t in info['topics_with_message_count']}
    assert {name: t['message_count'] for name, t in topics.items()} == {'/a': 60, '/b': 60}
    meta = topics['/a']['topic_metadata']
    assert meta['offered_qos_profiles'] == yaml.safe_load(offered_qos)
    assert (meta['type'], meta['serialization_format']) == ('std_msgs/msg/String', 'cdr')
    assert meta['type_description_hash'].startswith('RIHS01_')


def test_a_killed_bag_is_refused_before_the_reindex(killed_bag, typestore):
    with pytest.raises(FileNotFoundError, match='metadata'):
        read_texts(killed_bag.bag_dir, typestore)
    with pytest.raises(IncompleteFile):
        read_file_info(killed_bag.path)


def test_reindex_recovers_every_flushed_message_of_a_killed_bag(killed_bag, typestore):
    (recovery,) = reindex(killed_bag.bag_dir)
    assert read_texts(killed_bag.bag_dir, typestore) == killed_bag.texts
    assert (recovery.chunks, recovery.messages, recovery.dropped_tail_bytes) == (12, 120, 0)
    assert metadata(killed_bag.bag_dir)['message_count'] == 120


def _cut_points(written, count: int) -> list[int]:
    rng = np.random.default_rng(SEED)
    header_end = len(MAGIC) + 1
    return sorted(int(c) for c in rng.integers(header_end, written.flush_ends[-1], count))


@pytest.mark.parametrize('index', range(8))
def test_a_cut_anywhere_keeps_every_chunk_flushed_before_it(tmp_path, typestore, write_bag,
                                                            index):
    written = write_bag(tmp_path / 'bag', flushes=6, per_flush=7, close=False)
    cut = _cut_points(written, 8)[index]
    data = written.path.read_bytes()
    written.path.write_bytes(data[:cut])
    reindex(written.bag_dir)
    texts = read_texts(written.bag_dir, typestore)
    # Whole flushes before the cut are kept; a chunk whose message indexes were cut may be too.
    done = sum(1 for end in written.flush_ends if end <= cut)
    at_least = written.flushed_counts[done - 1] if done else 0
    at_most = written.flushed_counts[min(done, len(written.flushed_counts) - 1)]
    assert texts == written.texts[:len(texts)]
    assert at_least <= len(texts) <= at_most, (cut, len(texts))


@pytest.mark.parametrize('tail', [
    b'\x06' + b'\xff' * 8,  # a chunk whose length runs past the end
    b'\x06\x40\x00\x00\x00\x00\x00\x00\x00' + bytes(20),  # a chunk cut short
    b'\xab' * 300,  # an unknown opcode
    bytes(np.random.default_rng(SEED).integers(0, 256, 4096, dtype=np.uint8)),
])
def test_garbage_after_the_last_flush_is_dropped(killed_bag, typestore, tail):
    with killed_bag.path.open('ab') as file:
        file.write(tail)
    (recovery,) = reindex(killed_bag.bag_dir)
    assert read_texts(killed_bag.bag_dir, typestore) == killed_bag.texts
    assert recovery.dropped_tail_bytes == len(tail)


def test_a_chunk_failing_its_crc_is_left_out_and_the_rest_kept(killed_bag, typestore):
    data = bytearray(killed_bag.path.read_bytes())
    # Flip one payload byte in the middle of the 5th chunk (its framing stays whole).
    start, end = killed_bag.flush_ends[3], killed_bag.flush_ends[4]
    data[(start + end) // 2] ^= 0xFF
    killed_bag.path.write_bytes(bytes(data))
    (recovery,) = reindex(killed_bag.bag_dir)
    assert recovery.damaged_chunks == 1
    assert read_texts(killed_bag.bag_dir, typestore) == \
        killed_bag.texts[:40] + killed_bag.texts[50:]


def test_reindex_leaves_a_finished_bag_as_it_was(finished_bag):
    before = finished_bag.path.read_bytes()
    assert reindex(finished_bag.bag_dir) == []
    assert finished_bag.path.read_bytes() == before


def test_an_empty_file_becomes_an_empty_readable_bag(tmp_path, typestore):
    bag_dir = tmp_path / 'bag'
    bag_dir.mkdir()
    (bag_dir / 'bag_0.mcap').write_bytes(b'')
    reindex(bag_dir)
    assert read_texts(bag_dir, typestore) == []
    assert metadata(bag_dir)['message_count'] == 0


def test_a_directory_without_mcap_files_is_refused(tmp_path):
    with pytest.raises(FileNotFoundError, match='not a bag'):
        reindex(tmp_path)


def test_resuming_a_killed_bag_adds_its_next_file_with_the_recorded_qos(killed_bag, offered_qos):
    writer, known_qos = open_bag_file(killed_bag.bag_dir, resume=True)
    writer.close()
    assert writer.path.name == 'bag_1.mcap'
    assert known_qos == {'/a': offered_qos, '/b': offered_qos}
    assert read_file_info(killed_bag.path).message_count == 120  # reindexed on the way


def test_a_bag_of_several_files_reads_as_one(killed_bag, typestore, write_bag):
    reindex(killed_bag.bag_dir)
    second = write_bag(killed_bag.bag_dir, flushes=2, per_flush=5, first=1000)
    assert second.path.name == 'bag_1.mcap'
    assert read_texts(killed_bag.bag_dir, typestore) == killed_bag.texts + second.texts
    assert metadata(killed_bag.bag_dir)['relative_file_paths'] == ['bag_0.mcap', 'bag_1.mcap']


def test_every_message_keeps_its_sequence_number_and_publish_time(finished_bag):
    with finished_bag.path.open('rb') as file:
        messages = [m for _, _, m in make_reader(file).iter_messages()]
    assert [m.sequence for m in messages] == list(range(120))
    assert all(m.publish_time == m.log_time - 500 for m in messages)


def test_a_sequence_number_beyond_32_bits_wraps_as_mcap_stores_it(tmp_path, write_bag):
    written = write_bag(tmp_path / 'bag', flushes=1, per_flush=2, first=2**32 + 5)
    with written.path.open('rb') as file:
        assert [m.sequence for _, _, m in make_reader(file).iter_messages()] == [5, 6]


def test_the_recorders_account_is_summed_into_custom_data(killed_bag, write_bag):
    reindex(killed_bag.bag_dir)  # a killed file carries no account
    for first in (1000, 2000):
        write_bag(killed_bag.bag_dir, flushes=1, per_flush=2, first=first, recording={
            'missing:/a': '2', 'missing:/b': 'unchecked', 'lag_max_s:/a': f'{first / 1e4}'})
    custom = metadata(killed_bag.bag_dir)['custom_data']
    assert custom == {'missing:/a': '4', 'missing:/b': 'unchecked', 'lag_max_s:/a': '0.2'}
    assert recording_losses(custom) == {'/a': 4}
    assert loss_line(custom) == 'recording: LOST 4 messages: /a 4'


@pytest.mark.parametrize('custom, line', [
    ({'missing:/a': '0', 'missing:/b': '0'}, 'recording: 0 lost on 2 topics'),
    (None, 'recording: no account of loss (the recorder was killed before it closed the bag)'),
    # A bag of /diagnostics alone (several publishers): accounted for, nothing was killed.
    ({'missing:/diagnostics': 'unchecked', 'lag_max_s:/diagnostics': '0.01'},
     'recording: loss not counted (every topic has several publishers)'),
])
def test_a_run_says_what_it_lost(custom, line):
    assert loss_line(custom) == line


def test_bag_info_names_the_repair_for_a_killed_bag(killed_bag, capsys):
    assert cli.main(['bag', 'info', str(killed_bag.bag_dir)]) == 1
    assert 'wirefish bag reindex' in capsys.readouterr().err


def test_bag_reindex_then_info_shows_every_recovered_message(killed_bag, capsys):
    assert cli.main(['bag', 'reindex', str(killed_bag.bag_dir)]) == 0
    assert cli.main(['bag', 'info', str(killed_bag.bag_dir)]) == 0
    out = capsys.readouterr().out
    assert 'rebuilt from 12 intact chunks (120 messages)' in out
    assert 'Topic: /a | Type: std_msgs/msg/String | Count: 60' in out


def test_messages_whose_channel_was_in_a_damaged_chunk_are_counted_not_guessed(killed_bag,
                                                                               typestore):
    data = bytearray(killed_bag.path.read_bytes())
    data[killed_bag.flush_ends[0] // 2] ^= 0xFF  # the first chunk holds the schema and channels
    killed_bag.path.write_bytes(bytes(data))
    (recovery,) = reindex(killed_bag.bag_dir)
    assert (recovery.damaged_chunks, recovery.orphan_messages) == (1, 110)
    assert read_texts(killed_bag.bag_dir, typestore) == []


@pytest.mark.parametrize('names, ordered, following', [
    ([], [], 'bag_0.mcap'),
    (['bag_2.mcap', 'bag_10.mcap', 'bag_0.mcap'], ['bag_0.mcap', 'bag_2.mcap', 'bag_10.mcap'],
     'bag_11.mcap'),
    (['bag.mcap'], ['bag.mcap'], 'bag_0.mcap'),  # rosbags' name for a one-file bag
])
def test_split_files_are_ordered_by_index_and_the_next_one_is_new(tmp_path, names, ordered,
                                                                  following):
    bag_dir = tmp_path / 'bag'
    bag_dir.mkdir()
    for name in names:
        (bag_dir / name).write_bytes(b'')
    assert [p.name for p in storage_files(bag_dir)] == ordered
    assert next_file_path(bag_dir).name == following
