"""Writers: the only modules that write files."""

from facadecli.export.atomic import write_atomic

__all__ = ["write_atomic"]
