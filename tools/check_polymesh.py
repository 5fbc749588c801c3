#!/usr/bin/env python3
"""OpenFOAM reads the polyMesh `interpatch mesh` writes: checkMesh must say
"Mesh OK." of every volume example's mesh, whose points and cells are counted here
(checkMesh does not notice nodes left unmerged), the non-orthogonality and skewness
`interpatch info` reports must be checkMesh's, and potentialFoam runs on the graded
duct from its inlet (face w0) to its outlet (w1).

tools/check_polymesh.py INTERPATCH EXAMPLES_DIR WORK_DIR
OpenFOAM's environment is sourced here, from /usr/share/openfoam/etc/bashrc."""
import json
import os
import re
import shutil
import subprocess
import sys

cli, examples, work = sys.argv[1:4]
BASHRC = "/usr/share/openfoam/etc/bashrc"

CONTROL = """FoamFile { version 2.0; format ascii; class dictionary; object controlDict; }
application potentialFoam; startFrom startTime; startTime 0; stopAt endTime; endTime 1; deltaT 1;
writeControl timeStep; writeInterval 1; writeFormat ascii; writePrecision 12; writeCompression off;
timeFormat general; timePrecision 6; runTimeModifiable false;
"""
SCHEMES = """FoamFile { version 2.0; format ascii; class dictionary; object fvSchemes; }
ddtSchemes { default steadyState; }
gradSchemes { default Gauss linear; }
divSchemes { default none; div(phi,U) bounded Gauss linear; div(div(phi,U)) Gauss linear; }
laplacianSchemes { default Gauss linear corrected; }
interpolationSchemes { default linear; }
snGradSchemes { default corrected; }
"""
SOLUTION = """FoamFile { version 2.0; format ascii; class dictionary; object fvSolution; }
solvers { Phi { solver GAMG; smoother DIC; tolerance 1e-08; relTol 0.01; } p { $Phi; } }
potentialFlow { nNonOrthogonalCorrectors 3; }
"""


def foam(case, command):
    """An OpenFOAM tool run in `case` with OpenFOAM's environment; its output."""
    run = subprocess.run(["bash", "-c", f"source {BASHRC} >/dev/null 2>&1; cd '{case}' && {command}"],
                         capture_output=True, text=True)
    return run.returncode, run.stdout + run.stderr


def field(name, cls, dims, internal, patches):
    body = "".join(f"    {p} {{ {bc} }}\n" for p, bc in patches.items())
    return (f"FoamFile {{ version 2.0; format ascii; class {cls}; object {name}; }}\n"
            f"dimensions {dims};\ninternalField uniform {internal};\nboundaryField\n{{\n{body}}}\n")


def mesh_case(name):
    case = os.path.join(work, name)
    shutil.rmtree(case, ignore_errors=True)
    os.makedirs(os.path.join(case, "constant"))
    os.makedirs(os.path.join(case, "system"))
    for d, text in (("controlDict", CONTROL), ("fvSchemes", SCHEMES), ("fvSolution", SOLUTION)):
        with open(os.path.join(case, "system", d), "w") as f:
            f.write(text)
    spec = os.path.join(examples, name + ".json")
    subprocess.run([cli, "mesh", spec, "-o", os.path.join(case, "constant", "polyMesh")], check=True)
    info = json.loads(subprocess.run([cli, "info", spec], check=True, capture_output=True, text=True).stdout)
    return case, info


failures = []
for name in sorted(f[:-5] for f in os.listdir(examples) if f.endswith(".json")):
    with open(os.path.join(examples, name + ".json")) as f:
        spec = json.load(f)
    if spec.get("type") not in ("trilinear", "coons_volume", "hermite_volume", "loft_volume", "interpolate_volume",
                                "bspline_volume", "approximate_volume", "blocks"):
        continue
    case, info = mesh_case(name)
    mesh = info["mesh"]
    if spec["type"] == "blocks":
        # Merged: the blocks' nodes less those of their shared faces, counted here from
        # the blocks' own node counts (each shared face's nodes once).
        expected_points = sum(b["nodes"][0] * b["nodes"][1] * b["nodes"][2] for b in info["blocks"])
        for s in info["shared_faces"]:
            block = next(b for b in info["blocks"] if b["name"] == s["blocks"][0])
            d = "uvw".index(s["faces"][0][0])
            expected_points -= block["nodes"][0] * block["nodes"][1] * block["nodes"][2] // block["nodes"][d]
        expected_cells = sum((b["nodes"][0] - 1) * (b["nodes"][1] - 1) * (b["nodes"][2] - 1) for b in info["blocks"])
    else:
        nu, nv, nw = mesh["nodes"]
        expected_points, expected_cells = nu * nv * nw, (nu - 1) * (nv - 1) * (nw - 1)
    code, out = foam(case, "checkMesh")
    found = [re.search(rf"{k}:\s+(\d+)", out) for k in ("points", "cells")]
    points, cells = (int(m.group(1)) if m else -1 for m in found)
    ok = "Mesh OK." in out and code == 0
    counted = points == expected_points and cells == expected_cells
    print(f"{name}: checkMesh {'Mesh OK' if ok else 'FAILED'}, {points} points, {cells} cells"
          f"{'' if counted else f' (expected {expected_points} and {expected_cells})'}")
    # checkMesh prints 12 digits (writePrecision 12 above); the same formulas in
    # another order of summation differ in the last few of them.
    theirs = re.search(r"non-orthogonality Max: (\S+) average: (\S+)", out), re.search(r"Max skewness = (\S+)", out)
    ours = [mesh["non_orthogonality"]["max"], mesh["non_orthogonality"]["mean"], mesh["max_skewness"]]
    foam_values = [float(v) for m in theirs if m for v in m.groups()]
    agree = len(foam_values) == 3 and all(abs(a - b) <= 1e-9 * max(1.0, abs(b)) for a, b in zip(ours, foam_values))
    print(f"  non-orthogonality max, mean and skewness: info {ours}, checkMesh {foam_values}")
    if not ok or not counted or not agree:
        failures.append(name)
        print(out[-3000:])

def potential_flow(name, walls, inlet, outlet):
    """potentialFoam from `inlet` (1 m/s along x over its 1 m x 1 m face) to `outlet`,
    slip `walls`; the flux out, or None when the solver did not run."""
    case, _ = mesh_case(name)
    os.makedirs(os.path.join(case, "0"))
    slip = {p: "type slip;" for p in walls}
    with open(os.path.join(case, "0", "U"), "w") as f:
        f.write(field("U", "volVectorField", "[0 1 -1 0 0 0 0]", "(0 0 0)",
                      {**slip, inlet: "type fixedValue; value uniform (1 0 0);", outlet: "type zeroGradient;"}))
    with open(os.path.join(case, "0", "p"), "w") as f:
        f.write(field("p", "volScalarField", "[0 2 -2 0 0 0 0]", "0",
                      {**{p: "type zeroGradient;" for p in walls}, inlet: "type zeroGradient;",
                       outlet: "type fixedValue; value uniform 0;"}))
    code, out = foam(case, "potentialFoam -writephi")
    if code != 0 or "End" not in out:
        print(out[-3000:])
        return None
    with open(os.path.join(case, "0", "phi")) as f:
        phi = f.read()
    faces = phi[phi.index(outlet, phi.index("boundaryField")):]
    return sum(float(v) for v in faces[faces.index("(") + 1:faces.index(")")].split())


# The solver's answer, its face fluxes: what leaves through the outlet is what the
# inlet gives, 1 m/s over its 1 m x 1 m face (OpenFOAM's blockMesh duct of the same
# shape gives the same). One block, then the bend led into by a second block.
for name, walls, inlet, outlet in (("duct_graded", ("u0", "u1", "v0", "v1"), "w0", "w1"),
                                   ("blocks_bend", ("walls",), "inlet", "outlet")):
    outflow = potential_flow(name, walls, inlet, outlet)
    print(f"{name}: potentialFoam {'ran' if outflow is not None else 'FAILED'}, outflow {outflow} (inflow 1)")
    if outflow is None or abs(outflow - 1) >= 1e-6:
        failures.append(f"potentialFoam {name}")
sys.exit(f"failed: {', '.join(failures)}" if failures else 0)
