"""The proof: a conversion's source and output compiled by MuJoCo and compared, and the
commands that convert with it.

This layer sits above the readers (:mod:`robotwright.parsers`) and the writers
(:mod:`robotwright.generators`): it reads a source, writes the output, and compares the
two. Entry points:

- :func:`convert` (``robotwright convert``): read, write, prove; the output is placed
  only when the proof allows it (``strict``);
- :func:`prove`: the source and result models compared, every per-object array of
  ``MjModel`` by name (:func:`compare_models`);
- :func:`prove_urdf_output`: our URDF of an HRDF compared with our MJCF of it;
- :func:`roundtrip` (``robotwright roundtrip``): source -> HRDF -> our MJCF and URDF,
  compared with the source.

Modules: ``convert``, ``compare`` (the comparison), ``models`` (the two compiled models),
``families``, ``match``, ``objects`` (what is compared, matched by name), ``notes``
(differences a conversion explains), ``urdf_output``, and the ``roundtrip`` package.
A writer's check of its own output before placing it (``generators.compiles``, the USD
export's read-back in ``generators.usd_proof``) stays with the writer.
"""

from typing import TYPE_CHECKING

from robotwright._lazy import attach

if TYPE_CHECKING:
    from robotwright.proof.compare import compare_models, prove
    from robotwright.proof.convert import convert, file_kind, load_any
    from robotwright.proof.roundtrip import RoundTripReport, roundtrip
    from robotwright.proof.urdf_output import prove_urdf_output

__all__ = [
    "RoundTripReport",
    "compare_models",
    "convert",
    "file_kind",
    "load_any",
    "prove",
    "prove_urdf_output",
    "roundtrip",
]

attach(__name__, __file__)
