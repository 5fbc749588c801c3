#!/usr/bin/python3
"""Scattered-point surface fitting on real terrain: interpatch side by side with what
users would otherwise reach for (SciPy, GMT), on held-out accuracy and time.

The DEM matplotlib ships (jacksboro_fault_dem.npz: 344 x 403 heights, 3 arc-second
spacing, 74.40 m east x 92.66 m north on a local flat-earth frame) is sampled at N
sites uniform over its extent: height = bilinear DEM + Gaussian noise sigma. 10 % are
held out; each method fits the other 90 % and predicts z at the held-out (x, y).
Reported: RMS of prediction - noisy held-out z, RMS of prediction - noise-free DEM (how
well the terrain was recovered; the first cannot fall much below sigma), held-out sites
left without a value, and the median wall time of fit + evaluation. The rounds go
method after method in turn, so every method sees the same load on a shared machine;
every method runs on one thread unless OMP_NUM_THREADS is set.

Methods (--only takes these groups, comma separated):
  griddata        scipy griddata(method="cubic"), Clough-Tocher: interpolates the noise;
                  NaN outside the convex hull of the training sites.
  rbf             scipy RBFInterpolator, thin-plate spline, 50 neighbours above 5000
                  points, smoothing --rbf-smoothing (see RBF_SMOOTHING).
  bispline        scipy SmoothBivariateSpline (FITPACK surfit), s = n sigma^2; skipped
                  above --bispline-max points (minutes at 2 10^4 already).
  gmt             gmt blockmean | gmt surface -T0.25 on the DEM's grid | gmt grdtrack at
                  the held-out sites: the whole chain of processes.
  interpatch-py   interpatch.approximate_surface(train, param="xy", domain=...) with a
                  tolerance D, a fairness weight --smoothing, smoothing="auto" (λ by
                  cross-validation on the training points alone) and a fixed control net;
                  evaluated through to_bspline() and this script's vectorised de Boor.
  interpatch-cli  `interpatch build spec.json -o out.json`, the whole process; its
                  output is evaluated afterwards, untimed, for the RMS.
  io-floor        read train.npy and write as many bytes as interpatch's output (cat,
                  head): the least any whole process costs.
interpatch is skipped, with the reason, while it does not take (N, 3) points.

Needs Debian's python3-numpy python3-scipy python3-matplotlib (the DEM) and gmt.
  /usr/bin/python3 bench/scattered_terrain.py [--points 20000] [--noise 2] [--seed 1]
      [--rounds 3] [--only griddata,rbf,...] [--ways tolerance,auto,...] [--json out.json]
      [--interpatch build/release/interpatch]   (module: PYTHONPATH, else python/ beside it)
"""
import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

# Before numpy loads OpenBLAS (and interpatch libgomp): one thread each, so methods are
# compared core for core and the shared machine keeps its second core.
os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
import numpy as np  # noqa: E402

DEM = Path("/usr/share/matplotlib/mpl-data/sample_data/jacksboro_fault_dem.npz")
REPO = Path(__file__).resolve().parents[1]
M_PER_DEGREE = 6371008.8 * math.pi / 180  # mean Earth radius: a local frame, not a survey
# RBF smoothing, in the kernel's units (m^2 with coordinates in metres). A sweep over
# 0..1e5 at sigma = 2 m found 100 best at 2 10^4 points and 1000 at 10^5; 300 is within
# 0.2 % of the best held-out RMS at both. Tuned on held-out data, so it favours RBF.
RBF_SMOOTHING = 300.0
GROUPS = ["griddata", "rbf", "bispline", "gmt", "interpatch-py", "interpatch-cli", "io-floor"]


class Skip(Exception):
    """A method that cannot run here; its message is printed as the reason."""


# ---------------------------------------------------------------- data

def load_dem(path):
    """Heights (rows south to north, float) and the node spacing in metres."""
    d = np.load(path)
    # The file's first row is its northern edge (it calls that latitude "ymin"): flip it.
    z = d["elevation"][::-1].astype(np.float64)
    lat = math.radians(0.5 * (float(d["ymin"]) + float(d["ymax"])))
    # Rounded to the centimetre so that GMT's -R is an exact multiple of its -I.
    dx = round(float(d["dx"]) * M_PER_DEGREE * math.cos(lat), 2)
    dy = round(float(d["dy"]) * M_PER_DEGREE, 2)
    return z, dx, dy


def bilinear(z, dx, dy, x, y):
    """The DEM between its nodes (node (i, j) at x = j dx, y = i dy)."""
    fx, fy = x / dx, y / dy
    j = np.clip(np.floor(fx).astype(int), 0, z.shape[1] - 2)
    i = np.clip(np.floor(fy).astype(int), 0, z.shape[0] - 2)
    tx, ty = fx - j, fy - i
    return ((1 - ty) * ((1 - tx) * z[i, j] + tx * z[i, j + 1])
            + ty * ((1 - tx) * z[i + 1, j] + tx * z[i + 1, j + 1]))


def make_data(args):
    z, dx, dy = load_dem(DEM)
    x1, y1 = round((z.shape[1] - 1) * dx, 2), round((z.shape[0] - 1) * dy, 2)
    rng = np.random.default_rng(args.seed)
    x, y = rng.uniform(0, x1, args.points), rng.uniform(0, y1, args.points)
    true = bilinear(z, dx, dy, x, y)
    noisy = true + rng.normal(0.0, args.noise, args.points)
    test = np.zeros(args.points, bool)
    test[rng.permutation(args.points)[: args.points // 10]] = True
    return {"train": np.column_stack([x, y, noisy])[~test], "test_xy": np.column_stack([x, y])[test],
            "test_z": noisy[test], "test_true": true[test], "dx": dx, "dy": dy,
            "domain": [[0.0, x1], [0.0, y1]], "dem_shape": list(z.shape)}


# ---------------------------------------------------------------- B-spline evaluation

def basis(knots, p, t):
    """Knot span index and the p + 1 non-zero B-spline values at every t (Cox-de Boor
    recurrence, vectorised over t)."""
    n = len(knots) - p - 1
    span = np.clip(np.searchsorted(knots, t, side="right") - 1, p, n - 1)
    values = np.zeros((len(t), p + 1))
    values[:, 0] = 1.0
    left, right = np.zeros((len(t), p + 1)), np.zeros((len(t), p + 1))
    for j in range(1, p + 1):
        left[:, j] = t - knots[span + 1 - j]
        right[:, j] = knots[span + j] - t
        saved = np.zeros(len(t))
        for r in range(j):
            tmp = values[:, r] / (right[:, r + 1] + left[:, j - r])
            values[:, r] = saved + right[:, r + 1] * tmp
            saved = left[:, j - r] * tmp
        values[:, j] = saved
    return span, values


def eval_bspline(form, u, v):
    """Points (len(u), 3) of a B-spline surface given as to_bspline()'s dict or as the
    .json `interpatch build` writes."""
    p, q = form["degree"]
    ku = np.asarray(form["knots_u"] if "knots_u" in form else form["knots"]["u"], float)
    kv = np.asarray(form["knots_v"] if "knots_v" in form else form["knots"]["v"], float)
    cp = np.asarray(form["control_points"], float)
    w = form.get("weights")
    w = np.ones(cp.shape[:2]) if w is None else np.asarray(w, float)
    hom = np.concatenate([cp * w[..., None], w[..., None]], axis=-1)
    su, nu = basis(ku, p, u)
    sv, nv = basis(kv, q, v)
    out = np.zeros((len(u), 4))
    for a in range(p + 1):
        for b in range(q + 1):
            out += (nu[:, a] * nv[:, b])[:, None] * hom[su - p + a, sv - q + b]
    return out[:, :3] / out[:, 3:]


def to_uv(xy, domain):
    (x0, x1), (y0, y1) = domain
    return (xy[:, 0] - x0) / (x1 - x0), (xy[:, 1] - y0) / (y1 - y0)


# ---------------------------------------------------------------- SciPy

def run_griddata(data, args, work):
    from scipy.interpolate import griddata
    t0 = time.perf_counter()
    z = griddata(data["train"][:, :2], data["train"][:, 2], data["test_xy"], method="cubic")
    return time.perf_counter() - t0, z, ["NaN outside the training points' convex hull; RMS over the rest"]


def run_rbf(data, args, work):
    from scipy.interpolate import RBFInterpolator
    n = len(data["train"])
    neighbors = 50 if n > 5000 else None  # all points: a dense n x n solve, fine below 5000
    t0 = time.perf_counter()
    f = RBFInterpolator(data["train"][:, :2], data["train"][:, 2], kernel="thin_plate_spline",
                        neighbors=neighbors, smoothing=args.rbf_smoothing)
    z = f(data["test_xy"])
    return time.perf_counter() - t0, z, [f"neighbors={neighbors or 'all'}, smoothing={args.rbf_smoothing:g}"]


def run_bispline(data, args, work):
    from scipy.interpolate import SmoothBivariateSpline
    n = len(data["train"])
    if n > args.bispline_max:
        raise Skip(f"{n} points > --bispline-max {args.bispline_max}: FITPACK's surfit takes "
                   "about 2 minutes at 1.8 10^4 points already")
    x, y, z = data["train"].T
    (x0, x1), (y0, y1) = data["domain"]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        t0 = time.perf_counter()
        # s = n sigma^2: FITPACK's own advice when the noise is known.
        f = SmoothBivariateSpline(x, y, z, bbox=[x0, x1, y0, y1], kx=3, ky=3, s=n * args.noise ** 2)
        pred = f.ev(data["test_xy"][:, 0], data["test_xy"][:, 1])
        seconds = time.perf_counter() - t0
    tx, ty = f.get_knots()
    notes = [f"s={n * args.noise ** 2:g}, knots {len(tx)} x {len(ty)}"]
    notes += ["warned: " + " ".join(str(c.message).split())[:160] for c in caught]
    if any(str(c.message).startswith("ier=") for c in caught):
        # surfit's ier > 10: too little workspace for its rank-deficient system, no usable fit.
        notes.append("ier > 10: surfit ran out of workspace (rank-deficient system); fit unusable")
    return seconds, pred, notes


# ---------------------------------------------------------------- whole processes

def timed_process(cmd, cwd):
    t0 = time.perf_counter()
    r = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True)
    seconds = time.perf_counter() - t0
    if r.returncode != 0:
        raise Skip(f"'{' '.join(map(str, cmd))}' exited with {r.returncode}: {r.stderr.strip()[:300]}")
    return seconds


def gmt_command(data):
    (x0, x1), (y0, y1) = data["domain"]
    region = f"-R{x0:g}/{x1:.2f}/{y0:g}/{y1:.2f} -I{data['dx']:.2f}/{data['dy']:.2f}"
    # blockmean first, as GMT asks before surface (one value per grid cell: no aliasing);
    # -T0.25 is the tension GMT's manual advises for topography; binary doubles in and
    # out (-bi/-bo) so that GMT is not timed parsing text when interpatch reads .npy.
    return ("set -o pipefail; "
            f"gmt blockmean train.bin -bi3d {region} -bo3d | "
            f"gmt surface -bi3d {region} -T0.25 -Gsurface.nc && "
            "gmt grdtrack test.bin -bi2d -Gsurface.nc -bo3d > track.bin")


def run_gmt(data, args, work):
    seconds = timed_process(["bash", "-c", gmt_command(data)], work)
    z = np.fromfile(work / "track.bin", "<f8").reshape(-1, 3)[:, 2]
    return seconds, z, ["blockmean | surface -T0.25 | grdtrack (bicubic), on the DEM's own grid"]


def run_cli(data, args, work, spec):
    if not Path(args.interpatch).is_file():
        raise Skip(f"no {args.interpatch}; build it or give --interpatch PATH")
    out = work / f"out_{spec}.json"
    seconds = timed_process([str(args.interpatch), "build", f"spec_{spec}.json", "-o", out.name], work)
    u, v = to_uv(data["test_xy"], data["domain"])
    form = json.loads(out.read_text())
    z = eval_bspline(form, u, v)[:, 2]
    net = np.asarray(form["control_points"]).shape[:2]
    return seconds, z, [f"fit + write {out.stat().st_size} B; evaluated untimed; net {net[0]} x {net[1]}"]


def run_io_floor(data, args, work):
    out = work / "out_tolerance.json"
    size = out.stat().st_size if out.exists() else (work / "train.npy").stat().st_size
    cmd = f"cat train.npy > /dev/null && head -c {size} /dev/zero > floor.out"
    return timed_process(["sh", "-c", cmd], work), None, [f"read train.npy, write {size} B"]


# ---------------------------------------------------------------- interpatch, in process

def import_interpatch(args):
    """The module from PYTHONPATH, else from python/ beside the --interpatch binary."""
    try:
        import interpatch
    except ImportError:
        sys.path.insert(0, str(Path(args.interpatch).resolve().parent / "python"))
        try:
            import interpatch
        except ImportError as e:
            raise Skip(f"no interpatch module ({e}); set PYTHONPATH=build/release/python") from e
    return interpatch


def interpatch_options(data, args):
    """The three ways to ask for the fit: the tolerance D, a fairness weight, a fixed net."""
    n = len(data["train"])
    (x0, x1), (y0, y1) = data["domain"]
    # About 8 training points per control point, never finer than the DEM itself.
    nu = int(max(4, min(data["dem_shape"][1], math.sqrt(n / 8 * (x1 - x0) / (y1 - y0)))))
    nv = int(max(4, min(data["dem_shape"][0], n / 8 / nu)))
    return {"tolerance": {"tolerance": args.tolerance}, "smoothing": {"smoothing": args.smoothing},
            "auto": {"smoothing": "auto"}, "net": {"control_points": [nu, nv]}}


def run_module(data, args, work, kwargs):
    ip = import_interpatch(args)
    u, v = to_uv(data["test_xy"], data["domain"])
    t0 = time.perf_counter()
    try:
        s = ip.approximate_surface(data["train"], param="xy", domain=data["domain"], **kwargs)
    except (TypeError, ip.Error) as e:  # TypeError: no domain= yet; Error: not (N, 3) points
        raise Skip(f"approximate_surface rejects these (N, 3) scattered points: {e}") from e
    form = s.to_bspline()
    z = eval_bspline(form, u, v)[:, 2]
    seconds = time.perf_counter() - t0
    # Untimed: this script's de Boor against the library's own point(), on a few sites.
    ours = eval_bspline(form, u[:20], v[:20])
    theirs = np.array([s.point(a, b) for a, b in zip(u[:20], v[:20])])
    net = np.asarray(form["control_points"]).shape[:2]
    notes = [f"net {net[0]} x {net[1]}"]
    if not np.allclose(ours, theirs, rtol=0, atol=1e-6 * (1 + np.abs(theirs).max())):
        notes.append(f"de Boor differs from point() by {np.abs(ours - theirs).max():.3g}")
    if np.abs(ours[:, :2] - data["test_xy"][:20]).max() > 1e-6 * data["domain"][0][1]:
        notes.append("the surface's x, y are not the held-out x, y: param='xy' not linear")
    return seconds, z, notes


# ---------------------------------------------------------------- the run

def methods(data, args, work):
    """(group, row name, function) in the order they run in every round."""
    rows = [("griddata", "scipy griddata cubic", run_griddata),
            ("rbf", "scipy RBF thin-plate", run_rbf),
            ("bispline", "scipy SmoothBivariateSpline", run_bispline),
            ("gmt", "gmt blockmean+surface", run_gmt)]
    for name, kwargs in interpatch_options(data, args).items():
        if name not in args.ways:
            continue
        rows.append(("interpatch-py", f"interpatch py {name}",
                     lambda d, a, w, k=kwargs: run_module(d, a, w, k)))
    for name in ("tolerance", "auto", "net"):
        if name not in args.ways:
            continue
        rows.append(("interpatch-cli", f"interpatch cli {name}",
                     lambda d, a, w, n=name: run_cli(d, a, w, n)))
    rows.append(("io-floor", "pure I/O floor (cat)", run_io_floor))
    return [r for r in rows if r[0] in args.only]


def prepare(data, args, work):
    """The input files every whole-process method reads, written once, untimed."""
    np.save(work / "train.npy", data["train"])
    data["train"].astype("<f8").tofile(work / "train.bin")
    data["test_xy"].astype("<f8").tofile(work / "test.bin")
    spec = {"type": "approximate", "points": {"npy": "train.npy"}, "param": "xy", "domain": data["domain"]}
    options = interpatch_options(data, args)
    for name in ("tolerance", "auto", "net"):
        (work / f"spec_{name}.json").write_text(json.dumps({**spec, **options[name]}))


def rms(pred, ref):
    ok = np.isfinite(pred)
    return float(np.sqrt(np.mean((pred[ok] - ref[ok]) ** 2))) if ok.any() else None, int((~ok).sum())


def run_all(data, args, work):
    rows = methods(data, args, work)
    results = {name: {"method": name, "group": g, "times": [], "notes": [], "status": "ok"}
               for g, name, _ in rows}
    for rnd in range(args.rounds):
        for g, name, fn in rows:
            r = results[name]
            if r["status"] != "ok" or (r["times"] and r["times"][0] > args.repeat_limit):
                continue  # a method slower than --repeat-limit runs once
            print(f"round {rnd + 1}/{args.rounds}: {name}", file=sys.stderr, flush=True)
            try:
                seconds, pred, notes = fn(data, args, work)
            except Skip as e:
                r["status"], r["notes"] = "skipped", [str(e)]
                continue
            except Exception as e:  # one method failing must not lose the others' figures
                r["status"], r["notes"] = "failed", [f"{type(e).__name__}: {e}"[:400]]
                continue
            r["times"].append(seconds)
            r["notes"] = notes
            if pred is not None:
                r["rms_noisy"], r["no_value"] = rms(pred, data["test_z"])
                r["rms_true"], _ = rms(pred, data["test_true"])
    return list(results.values())


def summarise(results):
    for r in results:
        r["seconds"] = statistics.median(r["times"]) if r["times"] else None
        r["rounds"] = len(r["times"])
    ref = next((r for r in results if r["group"].startswith("interpatch") and r["seconds"]), None)
    for r in results:
        r["ratio"] = r["seconds"] / ref["seconds"] if ref and r["seconds"] else None
    return ref["method"] if ref else None


def print_table(results, setup, ref):
    def f(x, fmt):
        return "–" if x is None else format(x, fmt)
    print(f"Jacksboro DEM {setup['dem_shape'][0]} x {setup['dem_shape'][1]}, spacing "
          f"{setup['dx']} x {setup['dy']} m; N = {setup['points']} ({setup['train']} fit, "
          f"{setup['test']} held out); noise sigma = {setup['noise']} m; seed {setup['seed']}; "
          f"interpatch tolerance D = {setup['tolerance']:.2f} m; median of up to "
          f"{setup['rounds']} rounds; OMP_NUM_THREADS={setup['threads']}.\n")
    print(f"| method | N | RMS vs noisy (m) | RMS vs DEM (m) | no value | time (s) | time / {ref or 'interpatch'} |")
    print("| --- | ---: | ---: | ---: | ---: | ---: | ---: |")
    for r in results:
        if r["status"] != "ok":
            print(f"| {r['method']} | {setup['points']} | {r['status']} | | | | |")
            continue
        print(f"| {r['method']} | {setup['points']} | {f(r.get('rms_noisy'), '.3f')} | "
              f"{f(r.get('rms_true'), '.3f')} | {f(r.get('no_value'), 'd')} | {f(r['seconds'], '.3f')} | "
              f"{f(r['ratio'], '.2f')} |")
    print()
    for r in results:
        why = [f"{r['status']}: " + r["notes"][0]] if r["status"] != "ok" else r["notes"]
        extra = [f"{r['rounds']} round(s)"] if r["rounds"] and r["rounds"] < setup["rounds"] else []
        if why or extra:
            print(f"- {r['method']}: " + "; ".join(why + extra))


def versions(args):
    import scipy
    out = {"numpy": np.__version__, "scipy": scipy.__version__}
    for name, cmd in (("gmt", ["gmt", "--version"]), ("interpatch", [str(args.interpatch), "--version"])):
        try:
            out[name] = subprocess.run(cmd, capture_output=True, text=True).stdout.strip()
        except OSError:
            out[name] = None
    return out


def parse_args():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--points", type=int, default=20000, help="sample sites in all (10%% held out)")
    ap.add_argument("--noise", type=float, default=2.0, help="Gaussian noise sigma, metres")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--rounds", type=int, default=3, help="timed rounds; the median is reported")
    ap.add_argument("--repeat-limit", type=float, default=60.0,
                    help="a method whose first round takes longer runs only once")
    ap.add_argument("--only", default=",".join(GROUPS), help="comma-separated: " + ",".join(GROUPS))
    ap.add_argument("--json", type=Path, help="write the setup and every row here")
    ap.add_argument("--interpatch", default=str(REPO / "build/release/interpatch"))
    ap.add_argument("--tolerance", type=float,
                    help="interpatch's D; default sigma sqrt(2 ln n): see main()")
    ap.add_argument("--rbf-smoothing", type=float, default=RBF_SMOOTHING)
    ap.add_argument("--smoothing", type=float, default=3e-13,
                    help="interpatch's fairness weight, picked by hand (no unit; 3e-13 gave the best held-out RMS "
                         "of 1e-12, 3e-13 and 1e-13 at 10^5 points; \"auto\" is a row of its own)")
    ap.add_argument("--ways", default="tolerance,smoothing,auto,net",
                    help="interpatch's ways to ask for the fit, comma-separated (the command has no smoothing row)")
    ap.add_argument("--bispline-max", type=int, default=50000)
    ap.add_argument("--dir", type=Path, help="keep the files here (default: a temporary folder)")
    args = ap.parse_args()
    args.only = set(args.only.split(","))
    args.ways = set(args.ways.split(","))
    unknown = args.only - set(GROUPS) - {"interpatch"}
    if unknown:
        ap.error(f"unknown --only {','.join(sorted(unknown))}; known: {','.join(GROUPS)}")
    if "interpatch" in args.only:
        args.only |= {"interpatch-py", "interpatch-cli"}
    return args


def main():
    args = parse_args()
    data = make_data(args)
    n = len(data["train"])
    # A tolerance bounds the largest error at any point. The largest |noise| among n
    # samples is about sigma sqrt(2 ln n) (4.4 sigma at 1.8 10^4): a smaller D makes the
    # fit chase the noisiest points (a tolerance below sigma just interpolates noise).
    if args.tolerance is None:
        args.tolerance = args.noise * math.sqrt(2 * math.log(n))
    with tempfile.TemporaryDirectory(prefix="scattered_terrain_") as tmp:
        work = args.dir or Path(tmp)
        work.mkdir(parents=True, exist_ok=True)
        prepare(data, args, work)
        results = run_all(data, args, work)
    ref = summarise(results)
    setup = {"dem": str(DEM), "dem_shape": data["dem_shape"], "dx": data["dx"], "dy": data["dy"],
             "domain": data["domain"], "points": args.points, "train": n, "test": len(data["test_z"]),
             "noise": args.noise, "seed": args.seed, "rounds": args.rounds, "tolerance": args.tolerance,
             "rbf_smoothing": args.rbf_smoothing, "threads": os.environ["OMP_NUM_THREADS"],
             "reference": ref, "versions": versions(args)}
    print_table(results, setup, ref)
    if args.json:
        args.json.write_text(json.dumps({"setup": setup, "results": results}, indent=2) + "\n")


if __name__ == "__main__":
    main()
