"""Judge a sweep variant against the sweep it was replayed from: references reached, structure bests, priced time.

BASE is a whole `designopt sweep-structures` run; VARIANT a copy of it finished by a variant's checkout with
`--resume` after the rows of some stages were dropped (a replay: the stages before those are the base's own rows).
Per seed this prints how many of the large-budget references (``--references``, `sweep_reference.py --save`) each
reaches within ``--within``, the structures whose best full-path design cost moved by more than ``--margin`` either
way, and per stage the iterations of both and the variant's solve time *priced*: each of its solves' iterations at
the base's seconds per iteration of the same structure and stage (a stage the base lacks for that structure: the
base's rate of the structure's refine, else of the whole sweep). Two replays made side by side on a loaded machine
do not take comparable seconds; the same problem's time per iteration hardly depends on the variant. The kept
stages price to the base's own seconds exactly, so the priced total over the base's is the whole sweep's ratio.

    .venv/bin/python benchmarks/sweep_judge.py BASE/structures/s2158 REPLAY/structures/s2158 \
        --references benchmarks/reference/sweep_structures_k_i.csv
"""

from __future__ import annotations

import argparse
import signal
from pathlib import Path

import pandas as pd

from designopt.tables import stage_kind, structure_table


def structure_bests(summary: pd.DataFrame) -> pd.Series:
    """Each structure's best tracking full-path design cost (`tables.structure_table`; NaN if none tracks)."""
    return structure_table(summary).set_index("structure")["design_cost"]


def reached(bests: pd.Series, references: pd.Series, within: float) -> list[str]:
    """The structures of ``references`` (structure -> reference cost) whose best is within ``within`` x it."""
    return [s for s, ref in references.items() if bests.get(s, float("inf")) <= within * ref]


def moved(base: pd.Series, variant: pd.Series, margin: float) -> tuple[pd.Series, pd.Series]:
    """(lower, higher): the variant's best over the base's, for the structures lower or higher by more than
    ``margin`` (a fraction); a structure tracking in one run only is left out."""
    ratio = (variant / base).dropna()
    return ratio[ratio < 1 / (1 + margin)], ratio[ratio > 1 + margin]


def priced(base: pd.DataFrame, variant: pd.DataFrame) -> pd.DataFrame:
    """Per stage kind (`tables.stage_kind`, so ``screen2`` counts as ``screen``): solves, iterations and seconds of
    the base, and the variant's solves, iterations and seconds priced at the base's seconds per iteration of the
    same (structure, stage) -- else of the structure's ``refine``, else of the whole base run."""
    def rate(frame: pd.DataFrame) -> pd.Series:
        totals = frame.groupby(["structure", "stage"])[["solve_time_s", "iterations"]].sum()
        return totals["solve_time_s"] / totals["iterations"].where(totals["iterations"] > 0)

    per = rate(base).rename("per")
    refine = per.xs("refine", level="stage") if "refine" in set(base["stage"]) else pd.Series(dtype=float)
    overall = base["solve_time_s"].sum() / base["iterations"].sum()
    v = variant.join(per, on=["structure", "stage"])
    v["seconds"] = v["iterations"] * v["per"].fillna(v["structure"].map(refine)).fillna(overall)
    by_kind = [frame.groupby(frame["stage"].map(stage_kind)).agg(
        solves=("iterations", "size"), iterations=("iterations", "sum"), seconds=("seconds", "sum"))
        for frame in (base.assign(seconds=base["solve_time_s"]), v)]
    variant_columns = {"solves": "variant solves", "iterations": "variant iterations",
                       "seconds": "variant seconds (priced)"}
    return pd.concat([by_kind[0], by_kind[1].rename(columns=variant_columns)], axis=1).fillna(0)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("base", type=Path, help="the whole sweep's run directory")
    parser.add_argument("variant", type=Path, help="its replay by the variant")
    parser.add_argument("--references", type=Path, required=True, help="large-budget costs (structure,reference_cost)")
    parser.add_argument("--within", type=float, default=1.10)
    parser.add_argument("--margin", type=float, default=0.01)
    args = parser.parse_args()
    base, variant = (pd.read_csv(d / "summary.csv") for d in (args.base, args.variant))
    references = pd.read_csv(args.references).set_index("structure")["reference_cost"]
    bb, vb = structure_bests(base), structure_bests(variant)
    rb, rv = reached(bb, references, args.within), reached(vb, references, args.within)
    print(f"references within {args.within:.2f}x: base {len(rb)} of {len(references)}, variant {len(rv)}")
    for s in references.index:
        flag = "" if (s in rb) == (s in rv) else "  <- changed"
        ratios = (bb.get(s, float("nan")) / references[s], vb.get(s, float("nan")) / references[s])
        print(f"  {s:8s} {ratios[0]:.3f} -> {ratios[1]:.3f}x{flag}")
    lower, higher = moved(bb, vb, args.margin)
    print(f"structure bests lower / higher by more than {args.margin:.0%}: {len(lower)} / {len(higher)} of "
          f"{len((vb / bb).dropna())}")
    for name, part in (("lower", lower), ("higher", higher)):
        if len(part):
            print(f"  {name}: " + ", ".join(f"{s} {r:.3f}x" for s, r in part.sort_values().items()))
    table = priced(base, variant)
    print(table.to_string(float_format=lambda v: f"{v:.1f}"))
    total, new = table["seconds"].sum(), table["variant seconds (priced)"].sum()
    print(f"solver time {total:.0f} s -> {new:.0f} s priced ({new / total:.3f}x); iterations "
          f"{table['variant iterations'].sum() / table['iterations'].sum():.3f}x")


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
