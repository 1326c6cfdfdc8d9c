"""rosbag2 files through `rosbags` (pure Python): the type store that knows wirefish_msgs."""

from pathlib import Path

from ament_index_python.packages import get_package_share_directory
from rosbags.typesys import get_types_from_msg, get_typestore, Stores
from rosbags.typesys.store import Typestore

INTERFACE_PACKAGES = ('wirefish_msgs',)


def wirefish_typestore() -> Typestore:
    """
    Return the ROS 2 Jazzy type store extended with the workspace's own messages.

    The definitions are read from the installed ``.msg`` files, so a bag carries exactly the
    definitions the nodes were built with.
    """
    store = get_typestore(Stores.ROS2_JAZZY)
    types = {}
    for package in INTERFACE_PACKAGES:
        for path in sorted(Path(get_package_share_directory(package), 'msg').glob('*.msg')):
            types.update(get_types_from_msg(path.read_text(), f'{package}/msg/{path.stem}'))
    store.register(types)
    return store
