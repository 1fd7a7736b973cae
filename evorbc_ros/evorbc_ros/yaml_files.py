"""Parsing the YAML files users give, refusing what no settings file needs.

Anchors and aliases (``&a``, ``*a``) and merge keys (``<<``) are refused where the parser
meets them, before any value is built: an alias bomb (nine levels of nine aliases, 387
million strings from a few hundred bytes) or a recursive alias (``x: &a [*a]``) therefore
never expands, and no settings file needs either. A key given twice in one mapping is
refused (YAML keeps the last silently, so the first edit is lost), and nesting deeper than
:data:`evorbc_ros.limits.NESTING` is refused while composing, before Python's recursion
limit is reached (docs/design.md section 12).

libyaml (C) scans and parses when pyyaml has it; the events are composed into nodes here, in
Python, which is where the checks are made (measured in docs/performance.md).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import yaml
from yaml.composer import Composer
from yaml.constructor import SafeConstructor
from yaml.events import (
    AliasEvent,
    CollectionEndEvent,
    CollectionStartEvent,
    ScalarEvent,
    SequenceEndEvent,
    SequenceStartEvent,
)
from yaml.nodes import MappingNode, ScalarNode, SequenceNode
from yaml.resolver import Resolver

from evorbc_ros.input_files import gc_paused
from evorbc_ros.limits import NESTING, Limit

if yaml.__with_libyaml__:  # libyaml's parser: the same events as pyyaml's, several times faster
    from yaml._yaml import CParser as _Parser
else:  # pragma: no cover - pyyaml built without libyaml
    from yaml.parser import Parser
    from yaml.reader import Reader
    from yaml.scanner import Scanner

    class _Parser(Reader, Scanner, Parser):  # type: ignore[no-redef]
        def __init__(self, stream):
            Reader.__init__(self, stream)
            Scanner.__init__(self)
            Parser.__init__(self)


_MERGE_TAG = "tag:yaml.org,2002:merge"


class _StrictLoader(Composer, _Parser, SafeConstructor, Resolver):
    """A safe loader that composes with the checks of this module.

    ``error`` is raised with ``"<source>: ..."`` messages.
    """

    def __init__(
        self, text: str, source: str, error: type[Exception], counts: Mapping[str, Limit]
    ) -> None:
        _Parser.__init__(self, text)
        Composer.__init__(self)
        SafeConstructor.__init__(self)
        Resolver.__init__(self)
        self.source = source
        self.error = error
        self.depth = 0
        self.max_depth = _bound(NESTING, source, error)
        self.counts = counts
        self.counted: tuple[str, Limit] | None = None  # the next sequence's key and limit

    def _refuse(self, mark, problem: str) -> Exception:
        return self.error(f"{self.source}: line {mark.line + 1}: {problem}")

    def compose_node(self, parent, index):
        """One node, refusing aliases, anchors and nesting beyond the limit."""
        event = self.peek_event()
        if isinstance(event, AliasEvent) or (
            isinstance(event, (ScalarEvent, CollectionStartEvent)) and event.anchor is not None
        ):
            raise self._refuse(
                event.start_mark,
                "YAML anchors and aliases are not accepted; write the values out",
            )
        if isinstance(event, CollectionStartEvent):
            self.depth += 1
            if self.depth > self.max_depth:
                problem = NESTING.problem(self.depth)
                raise self._refuse(event.start_mark, f"nested too deeply: {problem}")
            if (
                self.depth == 2
                and isinstance(event, SequenceStartEvent)
                and isinstance(parent, MappingNode)
                and isinstance(index, ScalarNode)
                and index.value in self.counts
            ):
                self.counted = (index.value, self.counts[index.value])
            try:
                return super().compose_node(parent, index)
            finally:
                self.depth -= 1
        return super().compose_node(parent, index)

    def compose_sequence_node(self, anchor):
        """A sequence; that of a counted top-level key is refused over its limit.

        It is refused from the count of its items, before the rest are composed.
        """
        if self.counted is None:
            return super().compose_sequence_node(anchor)
        key, limit = self.counted
        self.counted = None
        bound = _bound(limit, self.source, self.error)
        start = self.get_event()
        tag = (
            start.tag
            if start.tag not in (None, "!")
            else self.resolve(SequenceNode, None, start.implicit)
        )
        node = SequenceNode(tag, [], start.start_mark, None, flow_style=start.flow_style)
        items = node.value
        while not self.check_event(SequenceEndEvent):
            if len(items) == bound:
                limit.check(bound + self._skip_items(), self.source, self.error, f"in {key}")
            items.append(self.compose_node(node, len(items)))
        node.end_mark = self.get_event().end_mark
        return node

    def _skip_items(self) -> int:
        """Consume the rest of the current sequence, its end included; its items left."""
        count, depth = 0, 0
        while True:
            event = self.get_event()
            if isinstance(event, CollectionStartEvent):
                count += depth == 0
                depth += 1
            elif isinstance(event, CollectionEndEvent):
                if depth == 0:
                    return count
                depth -= 1
            else:  # a scalar or an alias
                count += depth == 0

    def flatten_mapping(self, node) -> None:
        """Refuse merge keys (``<<``); they are the only thing pyyaml flattens."""
        for key_node, _ in node.value:
            if key_node.tag == _MERGE_TAG:
                raise self._refuse(
                    key_node.start_mark,
                    "YAML merge keys (<<) are not accepted; write the values out",
                )

    def construct_mapping(self, node, deep: bool = False) -> dict:
        """The mapping of ``node``, refusing a key that appears twice."""
        self.flatten_mapping(node)
        lines: dict[Any, int] = {}
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=True)
            line = key_node.start_mark.line + 1
            try:
                first = lines.get(key)
            except TypeError:  # unhashable: pyyaml's constructor names it below
                continue
            if first is not None:
                lines_ = f"lines {first} and {line}" if first != line else f"line {line}"
                raise self.error(f"{self.source}: key {key!r} appears twice ({lines_})")
            lines[key] = line
        return super().construct_mapping(node, deep=deep)


def _bound(limit: Limit, source: str, error: type[Exception]) -> int:
    try:
        return limit.value()
    except ValueError as e:  # its environment variable is not a positive integer
        raise error(f"{source}: {e}") from None


def parse_yaml(
    text: str, source: str, error: type[Exception], counts: Mapping[str, Limit] | None = None
) -> Any:
    """The data of the YAML document ``text`` read from ``source``.

    Args:
        counts: limits on the number of items of top-level sequences, by key (a maze's
            ``walls``): one over its limit is refused from the count, unbuilt.

    Raises:
        ``error``: in one line starting with ``source``: invalid YAML (with its line and
        column), an anchor, alias or merge key, a key given twice, nesting deeper than
        :data:`~evorbc_ros.limits.NESTING`, a sequence over its limit in ``counts``, or a
        document too large for memory.
    """
    loader = _StrictLoader(text, source, error, counts or {})
    try:
        with gc_paused():
            return loader.get_single_data()
    except yaml.YAMLError as e:
        mark = getattr(e, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        problem = getattr(e, "problem", None) or "invalid YAML"
        raise error(f"{source}: invalid YAML{where}: {problem}") from None
    except RecursionError:  # only with a recursion limit set far below NESTING's
        raise error(f"{source}: invalid YAML: nested too deeply") from None
    except MemoryError:
        raise error(f"{source}: cannot parse: the file does not fit in memory") from None
    finally:
        loader.dispose()
