"""The first stamp of the records the package makes (standard library only: the command line
reads it while building its parser, before anything heavy is imported)."""

from __future__ import annotations

DEFAULT_START_NS = 1_700_000_000 * 10**9
"""The first stamp (ns; 2023-11-14) of the bags `generate`, `import-csv`, `synthesize`,
`qualify` and a sweep's generated inputs write unless told: a real epoch time, so tools that
show dates show sensible ones."""
