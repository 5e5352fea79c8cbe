"""Writes models/nbarN.ron: IFToMM A02's pattern (models/n_four_bar.ron) with N four-bars:
N + 1 cranks of 1 m on the ground 1 m apart, N couplers of 1 m, each coupler's end pinned to
the next crank's (a loop each), 1 kg uniform links, gravity −y, started horizontal at
1 rad/s. Usage: python3 gen.py N [N ...]"""

import os
import sys

HALF_PI = "1.5707963267948966"


def model(n):
    lines = ["(", f'    name: "nbar{n}",', f'    description: "A02 with N = {n}.",']
    lines.append('    gravity: (0.0, -9.81, 0.0),')
    lines.append("    bodies: [")

    def body(name, parent, anchor, coordinate):
        return (
            f'        (name: "{name}", parent: "{parent}", mass: 1.0, com: (0.5, 0.0, 0.0), '
            f"inertia: Izz(0.08333333333333333), joint: (kind: Revolute, axis: (0.0, 0.0, 1.0), "
            f'anchor: ({anchor}, 0.0, 0.0), coordinate: "{coordinate}")),'
        )

    for i in range(n):
        lines.append(body(f"crank{i}", "ground", f"{float(i)}", f"c{i}"))
        lines.append(body(f"coupler{i}", f"crank{i}", "1.0", f"p{i}"))
    lines.append(body(f"crank{n}", "ground", f"{float(n)}", f"c{n}"))
    lines.append("    ],")
    lines.append("    loops: [")
    for i in range(n):
        lines.append(
            f'        (name: "pin{i}", kind: Revolute, a: (body: "coupler{i}", point: (1.0, 0.0, 0.0)), '
            f'b: (body: "crank{i + 1}", point: (1.0, 0.0, 0.0))),'
        )
    lines.append("    ],")
    q = [f'"c{i}": {HALF_PI}' for i in range(n + 1)] + [f'"p{i}": -{HALF_PI}' for i in range(n)]
    qd = [f'"c{i}": -1.0' for i in range(n + 1)] + [f'"p{i}": 1.0' for i in range(n)]
    lines.append("    initial: (")
    lines.append("        q: {" + ", ".join(q) + "},")
    lines.append("        qd: {" + ", ".join(qd) + "},")
    lines.append('        hold: ["c0"],')
    lines.append("    ),")
    lines.append("    simulation: (t_end: 20.0, dt_out: 0.05, rtol: 1e-9, atol: 1e-11),")
    lines.append(")")
    return "\n".join(lines) + "\n"


os.makedirs("models", exist_ok=True)
for n in map(int, sys.argv[1:]):
    with open(f"models/nbar{n}.ron", "w") as f:
        f.write(model(n))
