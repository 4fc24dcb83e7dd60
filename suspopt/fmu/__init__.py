"""A chosen design as an FMU (FMI 2.0, model exchange and co-simulation) generated as C source
from its element network: ``suspopt export SOURCE --fmu design.fmu`` (docs/guide/export-fmu.md).

- :mod:`.model`: the network as the C runtime takes it (structure and entries);
- :mod:`.params`: the parameters (the model's numeric config fields) and which entries follow
  each one, measured with the simulator's own builders;
- :mod:`.outputs`: the signal table as the runtime computes it;
- :mod:`.laws`: the semi-active control laws translated from their Python rules into C;
- :mod:`.modeldescription`, :mod:`.csource`, :mod:`.build`: modelDescription.xml, the
  sources (with ``runtime.c`` and the FMI headers shipped here) and the compiled binary;
- :mod:`.export`: the FMU file, written atomically.

Exporting needs no FMI tool; FMPy (the ``test`` and ``docs`` extras) checks and runs the FMUs.
"""

from .export import Exported, export_fmu, export_picks

__all__ = ["export_fmu", "export_picks", "Exported"]
