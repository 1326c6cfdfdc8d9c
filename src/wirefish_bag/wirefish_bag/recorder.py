# SPDX-License-Identifier: Apache-2.0
"""
Record the graph's topics into a rosbag2 bag (MCAP storage), like `ros2 bag record`.

Subscriptions are raw (serialised CDR bytes go into the bag untouched, no decode/encode cost),
with a QoS matched to each topic's publishers and a reader history QUEUE_DEPTH deep, and topics
that appear later are picked up by a periodic rescan, so the recorder can start before or after
the nodes. The rescan runs in a thread of its own while the loop below takes: on a loaded
machine a subscription costs 0.05-0.5 s (its type, its QoS from the graph, the reader), and a
graph that comes up brings some twenty topics at once, which kept the streams already recorded
waiting a second and more when the loop subscribed them itself.

No executor takes the messages: every POLL_PERIOD_S one loop takes everything each reader holds
(``take_message`` until it is empty) and writes it. An executor pays its wake-up, wait-set and
dispatch once per message (rclpy's classic executor ~0.5 ms of Python, the events executor
cannot give a callback the message info that carries the sequence number); the loop pays a
wake-up per period and a take per message, so a recorder that was starved for a moment takes
its backlog in one batch instead of falling further behind. A best-effort reader's history
holds QUEUE_DEPTH samples (10 s of the 100 Hz streams): far more than a period or a stall
(the recorder before this loop fell behind under load until that history overflowed). Writing
stays in the loop: ``mcap``'s encoder costs ~4 us a message (wirefish_bench.bench_recorder);
a writer thread would only add GIL hand-overs.

What arrived is flushed to the file every FLUSH_PERIOD_S, so a SIGKILL loses at most that much:
`wirefish bag reindex` makes the killed bag readable (wirefish_bag.reindex). A recorder
started with ``resume`` on such a bag reindexes it and goes on recording into its next file.
Before closing, the recorder drains its readers (``drain``): what was published before the stop
is in the bag. Each topic's account (messages missing from its publisher's sequence numbers,
the longest wait between publication and the bag) goes into the file's summary and
metadata.yaml's ``custom_data`` (wirefish_bag.bag_storage).
"""

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
import threading
import time
from typing import Any

from rclpy.node import Node
from rclpy.qos import DurabilityPolicy

from wirefish_bag.bag_storage import (add_topic, next_file_path, read_file_info,
                                      storage_files, write_metadata)
from wirefish_bag.bag_writer import BagFileWriter
from wirefish_bag.bagfile import wirefish_typestore
from wirefish_bag.offered_qos import offered_qos_yaml
from wirefish_bag.reindex import reindex
from wirefish_bag.sequence_gaps import recording_account, TopicAccount
from wirefish_common.topics import graph_topics, matching_qos, message_class

QUEUE_DEPTH = 1000
POLL_PERIOD_S = 0.05
# Half the ~1 s a kill may cost, so a recorder starved for a moment still keeps that bound.
FLUSH_PERIOD_S = 0.5
RESCAN_PERIOD_S = 0.5
# The longest a stop waits for the readers to give up what was published before it (inside
# the few seconds `wirefish up` gives each process to stop).
DRAIN_LIMIT_S = 3.0
# rmw's publication_sequence_number when the middleware gives none.
SEQUENCE_UNSUPPORTED = 2**64 - 1


@dataclass
class _Stream:
    topic: str
    subscription: Any
    channel: int
    account: TopicAccount


class BagRecorder(Node):
    """Subscribes to every topic under a namespace (and /diagnostics) and writes a bag."""

    def __init__(self, bag_path: Path, namespace: str, resume: bool = False,
                 announce: bool = True) -> None:
        """Open the bag (``record`` subscribes); ``announce``: log each topic it records."""
        # Nothing spins this node: parameter services would only hang their callers.
        super().__init__('wirefish_recorder', start_parameter_services=False)
        self._announce = announce
        self.bag_path = bag_path
        self._namespace = namespace
        self._typestore = wirefish_typestore()
        self._writer, self._known_qos = open_bag_file(bag_path, resume)
        self._streams: list[_Stream] = []
        # The writer, the streams and the accounts: the scan thread adds, the loop writes.
        self._lock = threading.Lock()
        self._seen: set[str] = set()
        self.accounts: dict[str, TopicAccount] = {}
        self._closed = False
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._scan_error: Exception | None = None
        self.first_message_ns: int | None = None

    def scan(self) -> None:
        """Subscribe to the topics that appeared since the last scan."""
        for topic, type_name in graph_topics(self, self._namespace).items():
            if topic in self._seen:
                continue
            self._seen.add(topic)
            try:
                msg_class = message_class(type_name)
                self._typestore.generate_msgdef(type_name, ros_version=2)
            except (ImportError, AttributeError, ValueError, KeyError) as error:
                self.get_logger().warning(f'cannot record {topic}: unknown type {type_name} '
                                          f'({type(error).__name__}: {error})')
                continue
            qos = self._known_qos.get(topic) or offered_qos_yaml(self, topic)
            qos_profile = matching_qos(self, topic, QUEUE_DEPTH)
            # A latched sample may be older than the recorder: its wait is no lag.
            latched = qos_profile.durability == DurabilityPolicy.TRANSIENT_LOCAL
            account = TopicAccount(latched=latched)
            # What arrives before the stream is added waits in the reader's history.
            subscription = self.create_subscription(
                msg_class, topic, _unused_callback, qos_profile, raw=True)
            with self._lock:
                channel = add_topic(self._writer, self._typestore, topic, type_name, qos)
                self.accounts[topic] = account
                self._streams.append(_Stream(topic, subscription, channel, account))
            if self._announce:
                self.get_logger().info(f'recording {topic} [{type_name}]')

    def _scan_until(self, stop: threading.Event) -> None:
        """
        Scan now and every RESCAN_PERIOD_S until ``stop``; keep what fails for ``record``.

        A scan that fails because the process shut rclpy down (a `wirefish mission` that gave
        up waiting for its graph) ends the scans quietly: the stop is on its way.
        """
        try:
            self.scan()
            while not stop.wait(RESCAN_PERIOD_S):
                self.scan()
        except Exception as error:  # raised again by the loop, which stops on it
            if self.context.ok():
                self._scan_error = error

    def take_all(self, published_before_ns: int | None = None) -> int:
        """
        Take and write everything the readers hold; return how many messages were taken.

        With ``published_before_ns``: count only those published before that time.
        """
        with self._lock:
            taken = self._take_all(published_before_ns)
        if taken and self.first_message_ns is None:
            self.first_message_ns = time.time_ns()
        return taken

    def _take_all(self, published_before_ns: int | None) -> int:
        taken = 0
        write = self._writer.write
        clock = time.time_ns
        for stream in self._streams:
            take = stream.subscription.handle.take_message
            msg_type = stream.subscription.msg_type
            account = stream.account
            while True:
                got = take(msg_type, True)
                if got is None:
                    break
                data, info = got
                now = clock()
                number = info['publication_sequence_number']
                if number == SEQUENCE_UNSUPPORTED:
                    number = None
                source_ns = info['source_timestamp']
                # The publisher's DDS sequence number is the MCAP message's: a bag shows its
                # gaps; its source timestamp is the publish time.
                write(stream.channel, now, data, number or 0, source_ns)
                account.count += 1
                account.sequence.add(number)
                if now - source_ns > account.lag_max_ns and not account.latched:
                    account.lag_max_ns = now - source_ns
                if published_before_ns is None or source_ns < published_before_ns:
                    taken += 1
        return taken

    def flush(self) -> None:
        """Write what was taken since the last flush to the file (it survives a SIGKILL)."""
        with self._lock:
            if not self._closed:
                self._writer.flush()

    def record(self, stopped: Callable[[], bool]) -> None:
        """Take and flush until ``stopped()`` (a thread rescans meanwhile), then drain."""
        stop_scan = threading.Event()
        scanner = threading.Thread(target=self._scan_until, args=(stop_scan,),
                                   name='recorder-scan', daemon=True)
        scanner.start()
        try:
            next_flush = time.monotonic() + FLUSH_PERIOD_S
            while not stopped() and self._scan_error is None:
                self.take_all()
                now = time.monotonic()
                if now >= next_flush:
                    self.flush()
                    next_flush = max(next_flush + FLUSH_PERIOD_S, now)
                time.sleep(max(0.0, POLL_PERIOD_S - (time.monotonic() - now)))
        finally:
            stop_scan.set()
            scanner.join()
        self.drain()
        if self._scan_error is not None:
            raise self._scan_error

    def drain(self) -> None:
        """
        Take what was published before now, until two takes a period apart find none of it.

        A message published before the stop may still be in transport when the first take
        empties the readers; the second take, a period later, finds it.
        """
        stop_ns = time.time_ns()
        deadline = time.monotonic() + DRAIN_LIMIT_S
        quiet = 0
        while quiet < 2 and time.monotonic() < deadline:
            quiet = quiet + 1 if self.take_all(stop_ns) == 0 else 0
            if quiet < 2:
                time.sleep(POLL_PERIOD_S)

    def start_thread(self) -> None:
        """Record in a thread of its own (beside a process's executor) until ``close``."""
        self._thread = threading.Thread(target=self.record, args=(self._stop.is_set,),
                                        name='recorder', daemon=True)
        self._thread.start()

    def count(self, topic: str) -> int:
        """Return how many messages of ``topic`` were taken so far."""
        account = self.accounts.get(topic)
        return 0 if account is None else account.count

    def total_count(self) -> int:
        """Return how many messages were taken so far, all topics."""
        with self._lock:
            return sum(account.count for account in self.accounts.values())

    def close(self) -> None:
        """Stop and drain the thread if any, then finish the bag; idempotent."""
        if self._thread is not None:
            self._stop.set()
            self._thread.join()
            self._thread = None
        with self._lock:
            if self._closed:
                return
            self._closed = True
            self._writer.close(recording_account(self.accounts))
        write_metadata(self.bag_path)


def _unused_callback(_data: bytes) -> None:
    """Never called: no executor spins the recorder (``BagRecorder.take_all`` takes)."""


def open_bag_file(bag_path: Path, resume: bool) -> tuple[BagFileWriter, dict[str, str]]:
    """
    Start the bag's next MCAP file; return its writer and the QoS already recorded per topic.

    A new bag gets its directory. ``resume`` on an existing bag first makes its files whole
    (a killed recorder's last file is reindexed), and the topics it holds keep the offered QoS
    they were recorded with, so every file of the bag describes a topic the same way.
    """
    known_qos: dict[str, str] = {}
    if resume and bag_path.is_dir() and storage_files(bag_path):
        reindex(bag_path)
        for path in storage_files(bag_path):
            for topic in read_file_info(path).topics:
                known_qos.setdefault(topic.name, topic.offered_qos_profiles)
    else:
        bag_path.mkdir(parents=True, exist_ok=resume)
    return BagFileWriter(next_file_path(bag_path)), known_qos


def main() -> int:
    """Entry point of the ``recorder`` executable: `wirefish record` as the graph's node."""
    from wirefish_bag.verb import record
    from wirefish_cli.api import verb_main
    return verb_main(record.add_arguments, record.run, 'recorder',
                     record.__doc__.strip().splitlines()[0])
