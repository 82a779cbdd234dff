"""Decoding a bag's CDR messages with the bag's own type definitions.

Every bag written by rosbag2 (and by :class:`~swarm_runtime.bag.BagWriter`) stores, per type,
its definition (an MCAP schema in ``ros2msg`` or ``ros2idl``) and, per topic, the RIHS01
hash of the type the publishers sent (metadata.yaml ``type_description_hash``, MCAP channel
``topic_type_hash``). Decoding never depends on which runtime or which installed message
packages the reading process has:

- The bag's definition is parsed and its RIHS01 hash computed. Where the bag records a
  hash, the definition must match it; if it does not, the definition does not describe the
  data and is not used (the workspace's definition is used if *it* matches the recorded
  hash; otherwise the topic cannot be decoded, :class:`~swarm_runtime.bag.BagTypeError`).
- A definition identical to this workspace's (same hash) decodes into the shared generated
  classes of :mod:`swarm_runtime.messages`; any other (an older swarm_interfaces, a robot's
  custom package) into classes generated from the bag's definition, with the same API.
- A bag without a definition for a type decodes it with the workspace's definition only when
  its recorded hash matches (or no hash is recorded).

The generated decoders check the CDR structure (string terminators, sequence lengths within
the data, no more than alignment padding left over), so bytes that do not fit the type raise
a :class:`~swarm_runtime.messages.DeserializationError` instead of decoding to wrong values.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from rosbags.typesys import Stores, TypesysError, get_types_from_idl, get_types_from_msg
from rosbags.typesys import get_typestore as rosbags_typestore
from rosbags.typesys.store import Typestore

from ..messages.fields import referenced_types
from .errors import BagTypeError

__all__ = [
    'Decoder',
    'TypeDecision',
    'definition_hash',
    'definition_typestore',
    'installed_definition',
]

_IDL_SEPARATOR = '=' * 80 + '\n'


def _parse(typename: str, encoding: str, text: str) -> dict[str, Any]:
    if encoding == 'ros2msg':
        return dict(get_types_from_msg(text, typename))
    if encoding in ('ros2idl', 'omgidl'):
        types: dict[str, Any] = {}
        for part in text.split(_IDL_SEPARATOR):
            body = part.split('\n', 1)[1] if part.startswith('IDL: ') else part
            if body.strip():
                types.update(get_types_from_idl(body))
        return types
    msg = f'definition encoding {encoding!r} is not supported'
    raise BagTypeError(msg)


def _excerpt(error: Exception, limit: int = 120) -> str:
    """The parser's complaint on one line, printable and short (it may quote damaged bytes)."""
    text = ' '.join(str(error).split())
    text = ''.join(c if c.isprintable() else '?' for c in text)
    return text if len(text) <= limit else text[: limit - 3] + '...'


def definition_typestore(
    typename: str, encoding: str, text: str, fallback: Typestore | None = None
) -> Typestore:
    """A typestore of one stored definition; dependencies it lacks come from ``fallback``.

    Raises:
        BagTypeError: the definition cannot be parsed or refers to unknown types.
    """
    try:
        types = _parse(typename, encoding, text)
    except TypesysError as err:
        msg = f'the definition of {typename} stored in the bag cannot be parsed ({_excerpt(err)})'
        raise BagTypeError(msg) from err
    if typename not in types:
        msg = f'the definition stored for {typename} does not define it'
        raise BagTypeError(msg)
    known = fallback.fielddefs if fallback is not None else {}
    missing = {n for defs in types.values() for n in referenced_types(defs[1])} - types.keys()
    while missing:
        name = missing.pop()
        if name not in known:
            msg = f'the definition of {typename} stored in the bag refers to unknown type {name}'
            raise BagTypeError(msg)
        types[name] = known[name]
        missing |= referenced_types(known[name][1]) - types.keys()
    typestore = rosbags_typestore(Stores.EMPTY)
    try:
        typestore.register(types)
    except TypesysError as err:
        msg = f'the definition of {typename} stored in the bag is invalid: {err}'
        raise BagTypeError(msg) from err
    return typestore


def definition_hash(typename: str, text: str, encoding: str = 'ros2msg') -> str:
    """RIHS01 hash of a ros2msg (or ros2idl) definition text.

    Raises:
        BagTypeError: the definition cannot be parsed.
    """
    from swarm_runtime.messages import default_registry

    store = definition_typestore(typename, encoding, text, default_registry().typestore)
    return str(store.hash_rihs01(typename))


@dataclass(frozen=True)
class TypeDecision:
    """How one topic's messages are decoded.

    ``source`` is 'workspace' (the shared generated classes) or 'bag' (classes generated
    from the bag's definition); ``verified`` says whether a recorded hash confirmed it.
    """

    typename: str
    source: str
    verified: bool
    decode: Callable[[bytes], Any]


class Decoder:
    """Chooses and caches the decoder of each (type, stored definition, recorded hash)."""

    def __init__(self) -> None:
        from swarm_runtime.messages import default_registry

        self._workspace = default_registry()
        self._decisions: dict[tuple[str, str, str, str], TypeDecision] = {}
        self._registries: dict[tuple[str, str, str], Any] = {}

    def _workspace_hash(self, typename: str) -> str | None:
        store = self._workspace.typestore
        if typename not in store.fielddefs:
            return None
        try:
            return str(store.hash_rihs01(typename))
        except (TypesysError, KeyError, ValueError):
            return None

    def decision(
        self, topic: str, typename: str, encoding: str, definition: str, recorded_hash: str
    ) -> TypeDecision:
        """Decide how messages of ``typename`` on ``topic`` are decoded.

        Raises:
            BagTypeError: no definition that fits the recorded data is available.
        """
        key = (typename, encoding, definition, recorded_hash)
        decision = self._decisions.get(key)
        if decision is None:
            decision = self._decide(topic, *key)
            self._decisions[key] = decision
        return decision

    def _decide(
        self, topic: str, typename: str, encoding: str, definition: str, recorded: str
    ) -> TypeDecision:
        ours = self._workspace_hash(typename)
        if definition.strip():
            store = definition_typestore(typename, encoding, definition, self._workspace.typestore)
            theirs = str(store.hash_rihs01(typename))
            if recorded and theirs != recorded:
                if ours == recorded:
                    return self._from_workspace(typename, verified=True)
                msg = (
                    f'{topic}: the definition of {typename} stored in the bag does not match the '
                    f'type hash recorded for it ({theirs} != {recorded}), and no other '
                    'definition with that hash is known: its messages cannot be decoded'
                )
                raise BagTypeError(msg)
            if theirs == ours:
                return self._from_workspace(typename, verified=bool(recorded))
            return self._from_bag(typename, encoding, definition, store, verified=bool(recorded))
        if ours is None:
            msg = (
                f'{topic}: the bag stores no definition of {typename} and it is not known '
                'here: its messages cannot be decoded'
            )
            raise BagTypeError(msg)
        if recorded and recorded != ours:
            msg = (
                f'{topic}: the bag stores no definition of {typename} and the one known here '
                f'has another type hash ({ours} != {recorded}): its messages cannot be decoded'
            )
            raise BagTypeError(msg)
        return self._from_workspace(typename, verified=bool(recorded))

    def _from_workspace(self, typename: str, *, verified: bool) -> TypeDecision:
        codec = self._workspace.codec(typename)
        return TypeDecision(typename, 'workspace', verified, codec.deserialize)

    def _from_bag(
        self, typename: str, encoding: str, definition: str, store: Typestore, *, verified: bool
    ) -> TypeDecision:
        from swarm_runtime.messages import MessageRegistry

        key = (typename, encoding, definition)
        registry = self._registries.get(key)
        if registry is None:
            registry = MessageRegistry(store)
            self._registries[key] = registry
        return TypeDecision(typename, 'bag', verified, registry.codec(typename).deserialize)


def _installed_msg_file(typename: str) -> Path | None:
    """``<prefix>/share/<pkg>/msg/<Name>.msg`` of an installed interface package, if any."""
    package, _, name = typename.split('/')
    prefixes = [p for p in os.environ.get('AMENT_PREFIX_PATH', '').split(os.pathsep) if p]
    prefixes.append(sys.prefix)
    for prefix in prefixes:
        candidate = Path(prefix) / 'share' / package / 'msg' / f'{name}.msg'
        if candidate.is_file():
            return candidate
    return None


def installed_definition(typename: str) -> tuple[str, str] | None:
    """rosbag2's definition text and RIHS01 hash of ``typename`` as installed on this machine.

    This is what ``ros2 bag record`` stores: the .msg files of the installed packages
    (found through ``AMENT_PREFIX_PATH`` and this Python's prefix), the type's own first and
    then every dependency. Dependencies without an installed file come from this workspace's
    definitions. None when the type's own file is not installed.
    """
    from swarm_runtime.messages import default_registry

    if _installed_msg_file(typename) is None:
        return None
    fallback = default_registry().typestore.fielddefs
    types: dict[str, Any] = {}
    queue = [typename]
    while queue:
        name = queue.pop()
        if name in types:
            continue
        path = _installed_msg_file(name)
        try:
            if path is not None:
                types.update(get_types_from_msg(path.read_text(encoding='utf-8'), name))
            elif name in fallback:
                types[name] = fallback[name]
            else:
                return None
        except (OSError, UnicodeDecodeError, TypesysError):
            return None
        queue.extend(referenced_types(types[name][1]) - types.keys())
    store = rosbags_typestore(Stores.EMPTY)
    try:
        store.register(types)
        text, _ = store.generate_msgdef(typename, ros_version=2)
        return str(text), str(store.hash_rihs01(typename))
    except (TypesysError, KeyError, ValueError):
        return None
