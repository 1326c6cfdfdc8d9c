# SPDX-License-Identifier: Apache-2.0
"""
A rosbag2 MCAP storage file written so that a killed writer loses at most one flush period.

The encoding is the maintained ``mcap`` library's (Foxglove, >= 1.6): messages collect in its
in-memory chunk; ``flush()`` (``mcap.writer.Writer.flush``) finishes the chunk, writes it with
its CRC and message indexes, and hands the bytes to the kernel, so whatever was flushed
survives a SIGKILL of the process. ``close()`` adds the summary (schemas, channels, chunk
indexes, statistics, the recording's own account as an MCAP metadata record) and the footer; a
file that never got them is made whole again by `wirefish bag reindex`
(wirefish_bag.reindex) from its intact chunks. Schemas and channels go into the chunk they
first appear in, so every chunk that survives carries what is needed to read its messages.

Why ``mcap`` rather than foxglove-sdk's writer (its Rust core costs ~1 us a message here
against ~5 us): its ``Channel.log`` takes no sequence number, and a bag keeps each message's
DDS publication sequence number, which is how its gaps are counted. Either is < 3 % of what
taking the message from the middleware costs (wirefish_bench.bench_recorder). Chunks stay
uncompressed, as rosbag2 writes them by default.
"""

from pathlib import Path

from mcap.writer import CompressionType, Writer

PROFILE = 'ros2'
LIBRARY = 'wirefish_bag'
# The file-level MCAP metadata record holding what the recorder counted (bag_storage reads it).
RECORDING_METADATA = 'wirefish_recording'
SEQUENCE_MODULUS = 2**32  # an MCAP message's sequence is a u32; DDS numbers are 64-bit


class BagFileWriter:
    """Writes one MCAP file (ros2 profile, CDR messages, uncompressed chunks)."""

    def __init__(self, path: Path) -> None:
        self.path = Path(path)
        self._file = self.path.open('xb')  # never overwrite a recording
        self._writer = Writer(self._file, compression=CompressionType.NONE)
        self._schemas: dict[str, int] = {}
        self._writer.start(PROFILE, LIBRARY)
        self._writer.flush()  # the header is on disk: a kill from now on leaves an MCAP file

    def add_schema(self, name: str, encoding: str, data: str) -> int:
        """Return the id of the schema ``name``, adding it on first use."""
        if name not in self._schemas:
            self._schemas[name] = self._writer.register_schema(name, encoding, data.encode())
        return self._schemas[name]

    def add_channel(self, topic: str, schema_id: int, metadata: dict[str, str],
                    encoding: str = 'cdr') -> int:
        """Add a channel (a topic with its type and offered QoS); return its id."""
        return self._writer.register_channel(topic, encoding, schema_id, metadata)

    def write(self, channel_id: int, time_ns: int, data: bytes, sequence: int = 0,
              publish_time_ns: int | None = None) -> None:
        """Add one serialised message (received at ``time_ns``) to the pending chunk."""
        self._writer.add_message(channel_id, time_ns, data,
                                 time_ns if publish_time_ns is None else publish_time_ns,
                                 sequence % SEQUENCE_MODULUS)

    def flush(self) -> None:
        """Write the pending chunk and its message indexes (nothing when it holds no message)."""
        self._writer.flush()

    def close(self, recording: dict[str, str] | None = None) -> None:
        """Write ``recording`` (a metadata record), the summary and the footer; idempotent."""
        if self._file.closed:
            return
        if recording:
            self._writer.add_metadata(RECORDING_METADATA, recording)
        self._writer.finish()
        self._file.close()
