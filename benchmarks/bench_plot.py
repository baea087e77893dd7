"""The default plot of a large scene: the N x N cloth (N = 50; ``--quick``: 20) simulated
with every output (``springc simulate`` without ``--vars``), then the plot of
``springc simulate --plot`` timed in parts: the choice of panels (copies found,
families), drawing the figure, and writing the PNG. Target: the 50x50 cloth's default
plot in under 5 s, with a legend or a colour bar.

The simulation is not timed (see ``bench_simulate.py``); it runs on the compiled engine
when numba is installed (dop853, the same steps as scipy's).
"""

from __future__ import annotations

import argparse
import io
import os
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SCENES = ROOT / "models" / "Scenes.mdl"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true", help="the 20x20 cloth")
    parser.add_argument("--side", type=int, help="rows and columns of the cloth")
    parser.add_argument("--out", help="also keep the PNG here")
    args = parser.parse_args()
    side = args.side or (20 if args.quick else 50)
    import springc
    from springc.simulation.figure import draw_layout
    from springc.simulation.plot_layout import HEATMAP, choose_layout

    load = os.getloadavg()[0]
    began = time.perf_counter()
    result = springc.simulate(str(SCENES), model_name="Scenes.Cloth",
                              parameters={"N": side, "M": side}, solver="dop853")
    simulated = time.perf_counter() - began
    t0 = time.perf_counter()
    layout = choose_layout(result.names, result.units, result.values)
    t1 = time.perf_counter()
    figure = draw_layout(result.model, result.time, result.values, layout, result.names)
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=100, pil_kwargs={"compress_level": 1})
    t2 = time.perf_counter()
    if args.out:
        Path(args.out).write_bytes(buffer.getvalue())
    maps = sum(1 for p in layout.panels if p.kind == HEATMAP)
    bars = len(figure.axes) - len(layout.panels)  # the axes beside the heat maps
    print(f"cloth {side}x{side}: {len(result.names):,} outputs x {len(result.time)} times "
          f"(simulated in {simulated:.1f} s), load average {load:.1f} at the start, "
          f"{os.getloadavg()[0]:.1f} at the end")
    print("| choose panels s | draw + PNG s | total s | panels | heat maps | colour bars "
          "| legends | PNG kB |\n| ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    legends = sum(1 for ax in figure.axes if ax.get_legend() is not None)
    print(f"| {t1 - t0:.2f} | {t2 - t1:.2f} | {t2 - t0:.2f} | {len(layout.panels)} | {maps} "
          f"| {bars} | {legends} | {len(buffer.getvalue()) // 1024} |")
    print(f"note: {layout.note}")


if __name__ == "__main__":
    main()
