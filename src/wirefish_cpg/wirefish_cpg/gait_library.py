# SPDX-License-Identifier: Apache-2.0
"""
The gait library: every successful fit kept with its wave, geometry, figures and time.

A gait is the CPG parameters fitted to one desired wave (eq 23) for one fish geometry (eqs 2-4),
with the fit's loss (eq 24, m*s) and swing-angle RMSE (section 5.2, deg). The library answers a
request for a wave it holds at once, but only for the same geometry: the same wave on another
fish asks other servo angles. Its YAML file (``FILE_FORMAT``, version ``FILE_VERSION``)::

    format: wirefish_gait_library
    version: 1
    gaits:
    - wave: {c1: 0.15, c2: 1.0, k: 8.0, frequency_hz: 1.0}
      geometry: {l1: 0.08, l2: 0.1, ...}        # the fields the fit used (m)
      params: {frequency_hz: ..., amplitude_1: ..., amplitude_2: ..., w12: ..., w21: ...,
               phi12: ..., phi21: ..., alpha: ...}
      loss: 0.000413
      rmse_theta_deg: [0.254, 0.864]
      fitted_at: '2026-12-01T07:00:00.000000+00:00'
      mode: phase_free                           # the fit mode; absent = phase_free

Floats are written as Python's repr, so a wave read back compares equal to the one stored.
``save_library`` writes atomically (a temporary file in the same directory, flushed and fsynced,
renamed over the old one, the directory fsynced): a crash at any moment leaves either the old
or the new file, never a part of one. Offsets are not stored (the fit assumes b = 0).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from datetime import datetime, timezone
import enum
import math
import os
from pathlib import Path
import tempfile

from wirefish_cpg.oscillator import CpgParameters
from wirefish_kinematics.wave_spec import WaveSpec

FILE_FORMAT = 'wirefish_gait_library'
FILE_VERSION = 1
WAVE_FIELDS = ('c1', 'c2', 'k', 'frequency_hz')
PARAMETER_FIELDS = ('frequency_hz', 'amplitude_1', 'amplitude_2', 'w12', 'w21', 'phi12',
                    'phi21', 'alpha')
LIBRARY_FILE = Path('wirefish') / 'gaits.yaml'
WORKSPACE_LIBRARY = Path('out') / 'gaits.yaml'  # in a colcon workspace
TEMPORARY_SUFFIX = '.tmp'


class FitMode(enum.StrEnum):
    """
    The problem a gait was fitted to: RetuneGait's ``mode``, the library file's ``mode``.

    ``wirefish_tuner.wave_loss`` defines both: PHASE_FREE (the default) scores the locked
    output, the robot's phase free; LITERAL is the paper's own problem. Defined here, beside
    the gaits that record it, because the fish reads the library without the tuner.
    """

    PHASE_FREE = 'phase_free'
    LITERAL = 'literal'


def default_library_path(environ: Mapping[str, str] | None = None,
                         package_prefix: Path | None = None) -> Path:
    """
    Return where the gait library is when no ``library_path`` names it.

    ``$ROS_HOME/wirefish/gaits.yaml`` when ROS_HOME is set (a ROS home of one's own: the tests
    give each test one); else the workspace's ``out/gaits.yaml``, the colcon workspace this
    package is installed in (``package_prefix``, found in the ament index when None), so two
    clones never answer with or replace each other's fits; else (installed outside a
    workspace) ``~/.ros/wirefish/gaits.yaml``.
    """
    environ = os.environ if environ is None else environ
    ros_home = environ.get('ROS_HOME')
    if ros_home:
        return Path(ros_home) / LIBRARY_FILE
    workspace = workspace_of(package_prefix if package_prefix is not None
                             else _installed_prefix())
    if workspace is not None:
        return workspace / WORKSPACE_LIBRARY
    return Path(environ.get('HOME', '~')).expanduser() / '.ros' / LIBRARY_FILE


def workspace_of(prefix: Path | None) -> Path | None:
    """Return the colcon workspace holding ``prefix`` (the parent of its install/ and src/)."""
    for directory in ([prefix, *prefix.parents] if prefix is not None else []):
        if directory.name == 'install' and (directory.parent / 'src').is_dir():
            return directory.parent
    return None


def _installed_prefix() -> Path | None:
    try:
        from ament_index_python.packages import get_package_prefix, PackageNotFoundError
    except ImportError:
        return None
    try:
        return Path(get_package_prefix('wirefish_cpg'))
    except PackageNotFoundError:
        return None


@dataclass(frozen=True)
class Gait:
    """One fitted gait: wave (eq 23), geometry fields (m), CPG parameters, figures, time."""

    wave: WaveSpec
    geometry: tuple[tuple[str, float], ...]
    params: CpgParameters
    loss: float
    rmse_theta_deg: tuple[float, float]
    fitted_at: str = field(default_factory=lambda: datetime.now(timezone.utc).isoformat())
    mode: str = FitMode.PHASE_FREE  # the fit mode (FitMode)

    def matches(self, wave: WaveSpec, geometry: dict[str, float],
                mode: str = FitMode.PHASE_FREE) -> bool:
        """Return whether this gait was fitted to exactly ``wave`` on ``geometry`` in ``mode``."""
        return (self.wave == wave and dict(self.geometry) == dict(geometry)
                and self.mode == mode)

    def to_record(self) -> dict:
        """Return the gait as the plain mapping stored in the YAML file."""
        p = self.params
        values = {'frequency_hz': p.frequency_hz, 'amplitude_1': p.amplitude[0],
                  'amplitude_2': p.amplitude[1], 'w12': p.w12, 'w21': p.w21,
                  'phi12': p.phi12, 'phi21': p.phi21, 'alpha': p.alpha}
        return {'wave': {name: float(getattr(self.wave, name)) for name in WAVE_FIELDS},
                'geometry': {name: float(value) for name, value in self.geometry},
                'params': {name: float(values[name]) for name in PARAMETER_FIELDS},
                'loss': float(self.loss),
                'rmse_theta_deg': [float(v) for v in self.rmse_theta_deg],
                'fitted_at': self.fitted_at, 'mode': str(self.mode)}

    @classmethod
    def from_record(cls, record: dict) -> Gait:
        """Return the gait of a stored mapping (raises ValueError naming what is wrong)."""
        try:
            wave = WaveSpec(**{name: float(record['wave'][name]) for name in WAVE_FIELDS})
            values = {name: float(record['params'][name]) for name in PARAMETER_FIELDS}
            params = CpgParameters(
                frequency_hz=values['frequency_hz'],
                amplitude=(values['amplitude_1'], values['amplitude_2']),
                w12=values['w12'], w21=values['w21'], phi12=values['phi12'],
                phi21=values['phi21'], alpha=values['alpha'])
            geometry = tuple(sorted((str(k), float(v)) for k, v in record['geometry'].items()))
            rmse = tuple(float(v) for v in record['rmse_theta_deg'])
            loss = float(record['loss'])
            fitted_at = str(record['fitted_at'])
            mode = str(record.get('mode', FitMode.PHASE_FREE))
        except (KeyError, TypeError, AttributeError) as error:
            raise ValueError(f'a gait record lacks or mistypes {error}') from error
        if len(rmse) != 2 or not math.isfinite(loss):
            raise ValueError('a gait record needs a finite loss and two RMSE values')
        return cls(wave=wave, geometry=geometry, params=params, loss=loss,
                   rmse_theta_deg=(rmse[0], rmse[1]), fitted_at=fitted_at, mode=mode)


def geometry_key(geometry: dict[str, float]) -> tuple[tuple[str, float], ...]:
    """Return a geometry mapping as the sorted (name, value) pairs a gait stores."""
    return tuple(sorted((str(k), float(v)) for k, v in geometry.items()))


@dataclass(frozen=True)
class GaitLibrary:
    """An immutable list of gaits, at most one per (wave, geometry)."""

    gaits: tuple[Gait, ...] = ()

    def find(self, wave: WaveSpec, geometry: dict[str, float], mode: str = FitMode.PHASE_FREE
             ) -> Gait | None:
        """Return the gait fitted to ``wave`` on ``geometry`` in ``mode``, or None."""
        return next((g for g in self.gaits if g.matches(wave, geometry, mode)), None)

    def with_gait(self, gait: Gait) -> GaitLibrary:
        """Return the library with ``gait`` added (replacing one for the same wave, geometry)."""
        kept = tuple(g for g in self.gaits
                     if not g.matches(gait.wave, dict(gait.geometry), gait.mode))
        return GaitLibrary(kept + (gait,))

    def for_geometry(self, geometry: dict[str, float]) -> tuple[Gait, ...]:
        """Return the gaits fitted on ``geometry``."""
        key = geometry_key(geometry)
        return tuple(g for g in self.gaits if g.geometry == key)


def library_from_document(document: object) -> GaitLibrary:
    """Return the library of a parsed YAML document (raises ValueError if it is not one)."""
    if document is None:
        return GaitLibrary()
    if not isinstance(document, dict) or document.get('format') != FILE_FORMAT:
        raise ValueError(f'not a {FILE_FORMAT} document')
    if document.get('version') != FILE_VERSION:
        raise ValueError(f'unknown {FILE_FORMAT} version {document.get("version")!r}')
    records = document.get('gaits') or []
    if not isinstance(records, list):
        raise ValueError('gaits must be a list')
    by_key: dict[tuple, Gait] = {}
    for record in records:  # a later record of the same wave and geometry wins, as in with_gait
        gait = Gait.from_record(record)
        by_key.pop((gait.wave, gait.geometry, gait.mode), None)
        by_key[gait.wave, gait.geometry, gait.mode] = gait
    return GaitLibrary(tuple(by_key.values()))


def load_library(path: Path) -> GaitLibrary:
    """Return the library stored at ``path`` (empty if there is no file; ValueError if bad)."""
    import yaml

    try:
        text = Path(path).read_text(encoding='utf-8')
    except FileNotFoundError:
        return GaitLibrary()
    try:
        document = yaml.load(text, Loader=getattr(yaml, 'CSafeLoader', yaml.SafeLoader))
    except yaml.YAMLError as error:
        raise ValueError(f'{path}: not YAML: {error}') from error
    try:
        return library_from_document(document)
    except ValueError as error:
        raise ValueError(f'{path}: {error}') from error


def library_document(library: GaitLibrary) -> dict:
    """Return the YAML document of ``library``."""
    return {'format': FILE_FORMAT, 'version': FILE_VERSION,
            'gaits': [g.to_record() for g in library.gaits]}


def save_library(library: GaitLibrary, path: Path) -> None:
    """Write ``library`` to ``path`` atomically (tmp, flush, fsync, rename, fsync the dir)."""
    import yaml

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    dumper = getattr(yaml, 'CSafeDumper', yaml.SafeDumper)
    descriptor, temporary = tempfile.mkstemp(prefix=f'.{path.name}.', suffix=TEMPORARY_SUFFIX,
                                             dir=path.parent)
    try:
        with os.fdopen(descriptor, 'w', encoding='utf-8') as stream:
            yaml.dump(library_document(library), stream, Dumper=dumper, sort_keys=False,
                      default_flow_style=None)
            stream.flush()
            os.fsync(stream.fileno())
        os.replace(temporary, path)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise
    directory = os.open(path.parent, os.O_RDONLY)
    try:
        os.fsync(directory)
    finally:
        os.close(directory)


class LibraryFile:
    """
    The library file one or more processes share: read when it changed, merged when written.

    ``current()`` re-reads the file only when its modification time or size changed (a stat,
    so a look-up stays in the milliseconds); ``add(gaits)`` takes an exclusive lock on
    ``<file>.lock``, merges the gaits into what the file holds now (another process, e.g.
    ``wirefish gaits build``, may have added some) and saves atomically.
    """

    def __init__(self, path: Path) -> None:
        """Refer to ``path`` (nothing is read until ``current`` or ``add``)."""
        self.path = Path(path)
        self._library = GaitLibrary()
        self._stamp: tuple[int, int] | None = None

    def _file_stamp(self) -> tuple[int, int] | None:
        try:
            status = self.path.stat()
        except FileNotFoundError:
            return None
        return status.st_mtime_ns, status.st_size

    def current(self) -> GaitLibrary:
        """Return the library as the file holds it now (ValueError if the file is bad)."""
        stamp = self._file_stamp()
        if stamp != self._stamp:
            self._library = load_library(self.path) if stamp is not None else GaitLibrary()
            self._stamp = stamp
        return self._library

    def add(self, gaits: list[Gait]) -> GaitLibrary:
        """Store ``gaits`` in the file (merged, atomic, under the lock); return the library."""
        import fcntl

        self.path.parent.mkdir(parents=True, exist_ok=True)
        with open(self.path.with_name(self.path.name + '.lock'), 'a') as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)
            self._stamp = None  # another writer may have saved since the last read
            library = self.current()
            # Under the lock no one else writes: a temporary file left now is a killed writer's.
            for stale in self.path.parent.glob(f'.{self.path.name}.*{TEMPORARY_SUFFIX}'):
                stale.unlink(missing_ok=True)
            for gait in gaits:
                library = library.with_gait(gait)
            save_library(library, self.path)
            self._library, self._stamp = library, self._file_stamp()
        return library


def tuner_library_path(params_file: Path) -> Path:
    """Return the gait library a graph's tuner uses: the file's library_path, or the default."""
    import yaml

    try:
        blocks = yaml.safe_load(Path(params_file).read_text())
    except (OSError, yaml.YAMLError):
        blocks = None
    named: dict[bool, str] = {}  # the graph's /** block first: the tuner's own block overrides it
    for key, block in (blocks.items() if isinstance(blocks, dict) else []):
        values = block.get('ros__parameters') if isinstance(block, dict) else None
        path = values.get('library_path') if isinstance(values, dict) else None
        if isinstance(path, str) and path and (key == '/**' or str(key).endswith('tuner_node')):
            named[key == '/**'] = path
    chosen = named.get(False, named.get(True))
    return Path(chosen) if chosen else default_library_path()
