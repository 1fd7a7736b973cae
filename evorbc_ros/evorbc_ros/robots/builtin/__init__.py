"""The robots evorbc ships, one registration module each (see :mod:`..registry`)."""
