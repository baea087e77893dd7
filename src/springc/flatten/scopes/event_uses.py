"""What flattening records about the event built-ins (see :mod:`.event_calls`)."""

from __future__ import annotations

from dataclasses import dataclass, field

from ...errors import Span


@dataclass
class EventUses:
    """Flattening state of the event built-ins: ``in_when`` > 0 while a when-clause's
    condition or body is evaluated; ``pre_uses``: (variable, span) of every ``pre``,
    ``edge`` or ``change`` outside a when-clause."""

    in_when: int = 0
    pre_uses: list[tuple[str, Span]] = field(default_factory=list)
