"""data_fetch's canonical writer: :class:`evinr_lite.io.canonical.CanonicalWriter` (which owns the layout)
raising data_fetch's :class:`~data_fetch.errors.ConversionError`, and refusing to write a recording that spans
no time."""
from __future__ import annotations

from evinr_lite.io import canonical

from .errors import ConversionError

__all__ = ["CanonicalWriter"]


class CanonicalWriter(canonical.CanonicalWriter):
    """:class:`evinr_lite.io.canonical.CanonicalWriter` whose problems are ``ConversionError``."""

    error = ConversionError

    def close(self):
        """As the kit's writer's, but a conversion whose events all share one timestamp is refused (the partial
        file dropped): nothing could be reconstructed from it, and a wrong --time-unit is its usual cause
        (decimal seconds read as 'ns' collapse to one instant), which the readers would only find later."""
        if not self.closed and self.n + self.buffered >= 2 and self.t_first == self.t_last:
            self.abort()
            raise self.error(f"all {self.n + self.buffered:,} events have the same timestamp ({self.t_first!r} s), so "
                             f"{self.out.name} would span no time and nothing could be reconstructed from it; the raw "
                             "timestamps are damaged, or read in the wrong unit (decimal seconds read as 'us' or 'ns' "
                             "collapse to one instant): give the unit they are written in (--time-unit, time_unit=), "
                             "or leave it out")
        return super().close()
