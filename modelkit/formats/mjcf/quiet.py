"""MuJoCo without side effects: its warnings become diagnostics instead of ``MUJOCO_LOG.TXT``.

MuJoCo's default warning handler prints the message and appends it to ``MUJOCO_LOG.TXT`` in the
working directory (``mju_writeLog``). ``validate`` and ``tree`` must never write a file, so while
modelkit calls MuJoCo a user warning handler (``mujoco.set_mju_user_warning``) collects the
messages; the previous handler is put back afterwards. (Errors already reach Python as exceptions.)

The bindings report a compiler warning (a deprecated attribute, say) as a Python ``UserWarning``
instead, which would otherwise be printed on stderr without a code: those are collected too, when
the block ends. The direct path (:mod:`.native`) receives the same messages through the handler.
"""

from __future__ import annotations

import contextlib
import warnings
from collections.abc import Iterator
from typing import Any


@contextlib.contextmanager
def collected_warnings(mujoco: Any) -> Iterator[list[str]]:
    """Collect MuJoCo's warnings into the yielded list; complete when the block has ended."""
    messages: list[str] = []
    previous = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(lambda message: messages.append(str(message).strip()))
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", UserWarning)
            yield messages
    finally:
        mujoco.set_mju_user_warning(previous)
    messages.extend(str(w.message).strip() for w in caught if issubclass(w.category, UserWarning))
