"""The USD reader: an OpenUSD robot read by Newton's USD importer into an HRDF.

Entry points: :func:`parse_usd` with :class:`USDOptions`, :func:`prepare_confined_read`
(import Newton before a confined read) and ``USD_SUFFIXES``. Most callers go through
:func:`robotwright.parsers.usd_to_hrdf`. Needs Newton and usd-core
(``pip install 'robotwright[usd]'`` on Python 3.12), imported only when a USD is read.
"""

from typing import TYPE_CHECKING

from robotwright._lazy import attach

if TYPE_CHECKING:
    from robotwright.parsers.usd.reader import (
        USD_SUFFIXES,
        USDOptions,
        parse_usd,
        prepare_confined_read,
    )

__all__ = ["USD_SUFFIXES", "USDOptions", "parse_usd", "prepare_confined_read"]

attach(__name__, __file__)
