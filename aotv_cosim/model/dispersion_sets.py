"""Dispersion sets: one file of dispersions that several scenarios share.

A scenario names it with `"dispersion_set": "dispersions/seed000_thesis.json"` (relative to the
scenario; schema `dispersions.schema.json`). The set's entries come first and in its order, then
the scenario's own `dispersions` replace an entry in place or follow. Draws are made in that
order from the run's seed (`campaigns.draws`), so scenarios flying different laws over one set
draw the same values for the same campaign seed and run index.
"""

from aotv_cosim.model.documents import load_document
from aotv_cosim.paths import regular_file, resolved


def dispersion_entries(doc: dict, path) -> dict:
    """{'comp.var': distribution} of a scenario document at `path`: its set's, then its own."""
    entries = {}
    if "dispersion_set" in doc:
        set_path = resolved(path.parent / doc["dispersion_set"], file=path, entry="dispersion_set",
                            what="dispersion set file")
        regular_file(set_path, what="dispersion set file (relative to the scenario)", file=path,
                     entry="dispersion_set")
        entries.update(load_document(set_path, "dispersions")["dispersions"])
    entries.update(doc.get("dispersions", {}))
    return entries
