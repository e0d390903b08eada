"""Each link's path of moving joints from the root, without copying a path per link.

The base decision (:mod:`modelkit.convert.base`) and the legged-robot checks (:mod:`modelkit.convert.legs`)
ask, of every link touching the ground, how many moving joints lie between it and the root, which is the
first, and where two such paths part. Listing the path of every link costs the square of a chain's length
(a 5,000-link chain lying on the floor took 33 s); here the moving joints form a tree of their own, each
link points at the nearest moving joint above it, and the questions are answered by climbing that tree
with binary lifting: O(log n) each, O(n log n) to build.
"""

from __future__ import annotations

from modelkit.model import Robot


class MovingPaths:
    """Root-first paths of moving joints, one per link (a link under no moving joint has the empty path)."""

    def __init__(self, robot: Robot) -> None:
        parent_joint = {joint.child: joint for joint in robot.joints}
        self._names: list[str] = []  # moving joint index → name
        self._depth: list[int] = []  # moving joint index → its path's length (1 for a first joint)
        up0: list[int] = []  # moving joint index → the moving joint above it (-1: none)
        index: dict[int, int] = {}  # id(joint) → moving joint index
        self._last: dict[str, int] = {}  # link → the nearest moving joint above it (-1: none)
        for link in [link.name for link in robot.links] + list(parent_joint):
            walk: list[str] = []
            on_walk: set[str] = set()
            current = link
            while current not in self._last and current in parent_joint and current not in on_walk:
                walk.append(current)
                on_walk.add(current)
                current = parent_joint[current].parent
            # ``current`` is settled, or a link hanging from nothing, or where the walk met itself (a cycle:
            # its links are taken as under no moving joint, as the root is)
            above = self._last.get(current, -1) if current not in on_walk else -1
            for name in reversed(walk):
                joint = parent_joint[name]
                if joint.type.moves:
                    if id(joint) not in index:
                        index[id(joint)] = len(self._names)
                        self._names.append(joint.name)
                        self._depth.append(1 + (self._depth[above] if above >= 0 else 0))
                        up0.append(above)
                    above = index[id(joint)]
                self._last[name] = above
            self._last.setdefault(link, above)  # a root, or a link settled by an earlier walk
        self._up = [up0]  # level k: the moving joint 2**k above (-1: none)
        while len(self._up) < max(1, max(self._depth, default=0).bit_length()):
            prev = self._up[-1]
            self._up.append([prev[p] if p >= 0 else -1 for p in prev])

    def length(self, link: str) -> int:
        """How many moving joints lie between the root and ``link``."""
        last = self._last.get(link, -1)
        return self._depth[last] if last >= 0 else 0

    def at(self, link: str, position: int) -> str:
        """The name of the moving joint at ``position`` (0: the first from the root) on ``link``'s path."""
        return self._names[self._ancestor(self._last[link], position + 1)]

    def shared(self, one: str, two: str) -> int:
        """How many moving joints the two links' paths share from the root."""
        a, b = self._last.get(one, -1), self._last.get(two, -1)
        if a < 0 or b < 0:
            return 0
        if self._depth[a] > self._depth[b]:
            a = self._ancestor(a, self._depth[b])
        elif self._depth[b] > self._depth[a]:
            b = self._ancestor(b, self._depth[a])
        if a == b:
            return self._depth[a]
        for level in reversed(range(len(self._up))):
            ua, ub = self._up[level][a], self._up[level][b]
            if ua != ub:
                a, b = ua, ub
        parent = self._up[0][a]
        return self._depth[parent] if parent >= 0 else 0

    def joints(self, link: str) -> list[str]:
        """The whole path, root first (for messages and tests; O(length))."""
        return [self.at(link, k) for k in range(self.length(link))]

    def _ancestor(self, node: int, depth: int) -> int:
        """The moving joint at ``depth`` on the path to ``node`` (its own depth or less)."""
        steps = self._depth[node] - depth
        level = 0
        while steps:
            if steps & 1:
                node = self._up[level][node]
            steps >>= 1
            level += 1
        return node
