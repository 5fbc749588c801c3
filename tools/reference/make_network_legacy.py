# One-off: networks whose curves cross at common parameters, built by interpatch
# 04f53ee (before curves were re-expressed), kept as fixtures for bit-identity.
import json, math, random, shutil, subprocess, sys
out = sys.argv[1]; exe = sys.argv[2]
random.seed(15)
def surf(a, b, c):
    return lambda u, v: [3*u + 0.2*math.sin(2*v), 2*v + 0.1*u*v, a*math.sin(b*u)*math.cos(c*v) + 0.3*u*u]
def curve(pts, deg, closed=False):
    d = {"interpolate": pts, "degree": deg, "param": "uniform"}
    if closed: d["periodic"] = True
    return d
cases = []
for k, (nu, nv, method, given, deg) in enumerate([(5, 4, "gordon", False, 3), (6, 5, "coons_linear", True, 3),
        (4, 7, "coons_hermite", False, 2), (3, 3, "gordon", True, 3), (7, 6, "gordon", False, 2)]):
    f = surf(random.uniform(0.5, 1.5), random.uniform(1, 3), random.uniform(1, 3))
    us = [i/(nu-1) for i in range(nu)]; vs = [j/(nv-1) for j in range(nv)]
    # u-curve j samples (m-1) * (nu-1) + 1 points so the crossings are at sample points.
    uc = []
    for j, v in enumerate(vs):
        m = 2 + (j % 3)
        n = m*(nu-1)+1
        uc.append(curve([f(i/(n-1), v) for i in range(n)], deg))
    vc = []
    for i, u in enumerate(us):
        m = 2 + (i % 2)
        n = m*(nv-1)+1
        vc.append(curve([f(u, j/(n-1)) for j in range(n)], deg))
    s = {"type": "network", "method": method, "u_curves": uc, "v_curves": vc}
    if given: s["u_params"] = us; s["v_params"] = vs
    cases.append((f"common_{k}", s))
# a closed network: sections of a tube
secs = []
for j in range(4):
    z = j/3.0; r = 1 + 0.3*z
    secs.append(curve([[r*math.cos(2*math.pi*i/8), (0.8+0.2*z)*math.sin(2*math.pi*i/8), z] for i in range(8)], 3, True))
along = []
for i in range(8):
    a = 2*math.pi*i/8
    along.append(curve([[(1+0.3*z)*math.cos(a), (0.8+0.2*z)*math.sin(a), z] for z in [t/6 for t in range(7)]], 3))
cases.append(("closed_0", {"type": "network", "method": "coons_linear", "periodic": [True, False], "u_curves": secs, "v_curves": along}))
for name in ["network_gordon", "network_coons", "network_closed"]:
    cases.append((name, json.load(open(f"examples/{name}.json"))))
for name, s in cases:
    s.pop("comment", None)
    json.dump(s, open(f"{out}/{name}.json", "w"))
    subprocess.run([exe, "build", f"{out}/{name}.json", "-o", f"{out}/{name}.npz"], check=True)
    print(name)
