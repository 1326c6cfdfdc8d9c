# SPDX-License-Identifier: Apache-2.0
"""rosbag2 files through `rosbags` (pure Python): the type store that knows wirefish_msgs."""

from dataclasses import dataclass
from pathlib import Path

from ament_index_python.packages import get_package_share_directory
from rosbags.highlevel import AnyReader
from rosbags.typesys import get_types_from_msg, get_typestore, Stores
from rosbags.typesys.store import Typestore

INTERFACE_PACKAGES = ('wirefish_msgs',)


def wirefish_typestore() -> Typestore:
    """
    Return the ROS 2 Jazzy type store extended with the workspace's own messages.

    The definitions are read from the installed ``.msg`` and ``.action`` files, so a bag
    carries exactly the definitions the nodes were built with. An action's feedback topic
    (``<action>/_action/feedback``) carries ``<pkg>/action/<Name>_FeedbackMessage``: the goal's
    UUID and the feedback section of the ``.action`` file.
    """
    store = get_typestore(Stores.ROS2_JAZZY)
    types = {}
    for package in INTERFACE_PACKAGES:
        share = Path(get_package_share_directory(package))
        for path in sorted((share / 'msg').glob('*.msg')):
            types.update(get_types_from_msg(path.read_text(), f'{package}/msg/{path.stem}'))
        for path in sorted((share / 'action').glob('*.action')):
            types.update(action_feedback_types(package, path.stem, path.read_text()))
    store.register(types)
    return store


def action_feedback_types(package: str, action: str, text: str) -> dict:
    """
    Return the types of ``action``'s feedback message, from its ``.action`` text.

    The feedback section is named ``<pkg>/msg/<Action>_Feedback`` in the bag's definitions:
    rosbags writes nested types only under ``msg`` (the bytes on the wire are the same).
    """
    feedback_section = text.split('\n---\n')[2]
    feedback = f'{package}/msg/{action}_Feedback'
    types = dict(get_types_from_msg(feedback_section, feedback))
    types.update(get_types_from_msg(f'unique_identifier_msgs/UUID goal_id\n{feedback} feedback',
                                    f'{package}/action/{action}_FeedbackMessage'))
    return types


@dataclass
class Bag:
    """All messages of a bag, decoded: {topic: [(receive time s, message), ...]}."""

    path: Path
    types: dict[str, str]
    messages: dict[str, list]
    start_s: float
    duration_s: float


def read_bag(path: Path, topics: list[str] | None = None) -> Bag:
    """Read and decode every message (optionally only ``topics``) of a rosbag2 bag."""
    store = wirefish_typestore()
    with AnyReader([Path(path)], default_typestore=store) as reader:
        connections = [c for c in reader.connections if topics is None or c.topic in topics]
        types = {c.topic: c.msgtype for c in connections}
        messages: dict[str, list] = {topic: [] for topic in types}
        for connection, timestamp, raw in reader.messages(connections=connections):
            messages[connection.topic].append(
                (timestamp * 1e-9, reader.deserialize(raw, connection.msgtype)))
        return Bag(Path(path), types, messages, reader.start_time * 1e-9,
                   (reader.end_time - reader.start_time) * 1e-9)
