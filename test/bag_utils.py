"""Checks of recorded bags for the cross-process tests (recorder kill, graph kill, e2e)."""

from pathlib import Path
import subprocess
import sys

from wirefish_bringup.bagfile import read_bag
import yaml


def reindex_bag(bag_path: Path, env: dict[str, str] | None = None) -> str:
    """Run the documented repair step, `wirefish bag reindex BAG`; return what it printed."""
    result = subprocess.run(
        [sys.executable, '-m', 'wirefish_bringup.cli', 'bag', 'reindex', str(bag_path)],
        env=env, capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stdout + result.stderr
    return result.stdout


def assert_bag_readable(bag_path: Path) -> dict[str, int]:
    """
    Assert that rosbags opens the bag and decodes every message; return messages per topic.

    metadata.yaml must count exactly what the files hold (what `ros2 bag info` would show).
    """
    bag = read_bag(Path(bag_path))  # decodes every message: a damaged one raises here
    counts = {topic: len(messages) for topic, messages in bag.messages.items()}
    info = yaml.safe_load((Path(bag_path) / 'metadata.yaml').read_text())
    listed = {entry['topic_metadata']['name']: entry['message_count']
              for entry in info['rosbag2_bagfile_information']['topics_with_message_count']}
    assert counts == listed, f'metadata.yaml {listed} but the files hold {counts}'
    return counts


def counters(bag_path: Path, topic: str) -> list[int]:
    """Return the counter that ros_peers' body_wave_talker puts in y[2], per recorded message."""
    return [int(msg.y[2]) for _, msg in read_bag(Path(bag_path), [topic]).messages[topic]]
