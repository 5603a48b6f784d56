"""Fixed-joint policies of the URDF parser.

- ``"keep"`` (default): every link stays a body; a fixed joint is a body without joints.
- ``"merge"``: a link attached by a fixed joint is merged into its parent body: masses,
  centres of mass and inertia tensors are combined exactly in the parent frame (the
  child's rotation is applied to its tensor before the parallel-axis shift), its geoms
  are re-posed into the parent, and its frame is kept as a site named after the link.
- ``"site"``: only a massless leaf link on a fixed joint (the usual way URDFs mark sensor
  and tool frames) becomes a site on its parent; its geoms move to the parent.

The root link is never merged away.
"""

from __future__ import annotations

from typing import Literal

FixedPolicy = Literal["keep", "merge", "site"]
FIXED_POLICIES: tuple[str, ...] = ("keep", "merge", "site")
