#!/usr/bin/env python3
"""The environment light's benchmark (issue 17), printing the figures docs/environment.md quotes.

1. Error at equal time: scenes/tests/env_bench.gltf (a Lambert floor, a Lambert sphere, a glossy
   metal sphere) under tools/make_env_maps.py's sun.hdr (a sky and a sun of 2 x 2 texels at 10^4 x
   the sky's mean). `render --time T` with --lighting mis (environment importance sampling + BSDF
   sampling, MIS) against --lighting bsdf (BSDF sampling alone), interleaved repeats; relMSE
   against a converged MIS reference (`nusselt diff`: mean of (x - ref)^2 / (ref^2 + 0.01)); the
   median of each and their ratio (the goal: >= 10).
2. Speed: samples per CPU second of the same scene lit by the environment (env_bench.gltf --env
   sun.hdr) and by an area light instead (env_bench_area.gltf --env none), interleaved; the goal:
   the environment within 15 %. CPU time, not wall time: on a shared machine the wall time of a
   render varied 2x run to run, its CPU time (lavapipe renders on the process's threads) far less.
3. Light selection with both (env_bench_area.gltf --env sun.hdr): relMSE at equal time of
   --env-select half against --env-select power.

usage: python3 tools/bench_env.py [--nusselt build/nusselt] [--time 4] [--repeats 3] [--quick]
Standard library only. References are cached in --work (default /tmp/nusselt-bench-env).
"""
import argparse
import os
import re
import resource
import statistics
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import make_env_maps  # noqa: E402


def run(cmd):
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if r.returncode != 0:
        sys.exit("failed: %s\n%s" % (" ".join(cmd), r.stderr))
    return r.stdout + r.stderr


def info_value(nusselt, exr, name):
    out = run([nusselt, "info", exr])
    m = re.search(r"^\s*%s: (\S+)" % re.escape(name), out, re.M)
    return m.group(1) if m else None


def rel_mse(nusselt, exr, ref):
    out = run([nusselt, "diff", exr, ref])
    return float(re.search(r"relMSE (\S+)", out).group(1))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--nusselt", default=os.path.join(ROOT, "build", "nusselt"))
    ap.add_argument("--time", type=float, default=4.0, help="seconds per equal-time render")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--width", type=int, default=96)
    ap.add_argument("--height", type=int, default=64)
    ap.add_argument("--ref-spp", type=int, default=4096)
    ap.add_argument("--speed-spp", type=int, default=128)
    ap.add_argument("--work", default="/tmp/nusselt-bench-env")
    ap.add_argument("--quick", action="store_true", help="tiny settings (a smoke test of the script)")
    ap.add_argument("--only-speed", action="store_true", help="section 2 only")
    a = ap.parse_args()
    if a.quick:
        a.time, a.repeats, a.width, a.height, a.ref_spp, a.speed_spp = 0.5, 1, 24, 16, 64, 16
    os.makedirs(a.work, exist_ok=True)
    sun = os.path.join(a.work, "sun.hdr")
    make_env_maps.sun_map(sun)
    scenes = os.path.join(ROOT, "scenes", "tests")
    env_scene = os.path.join(scenes, "env_bench.gltf")
    area_scene = os.path.join(scenes, "env_bench_area.gltf")
    common = ["--width", str(a.width), "--height", str(a.height), "--max-depth", "4", "-q", "--checkpoint", "0"]
    device = run([a.nusselt, "devices"]).splitlines()[0]
    print("device:", device)
    print("load average at start: %.2f %.2f %.2f" % os.getloadavg())

    def reference(scene, extra, tag):
        path = os.path.join(a.work, "ref-%s-%dx%d-%d.exr" % (tag, a.width, a.height, a.ref_spp))
        if not os.path.exists(path):
            t0 = time.time()
            run([a.nusselt, "render", scene, "-o", path, "--spp", str(a.ref_spp), "--seed", "999"] + common + extra)
            print("reference %s: %d spp in %.0f s" % (tag, a.ref_spp, time.time() - t0))
        return path

    def equal_time(scene, extra, ref, variants):
        errors = {name: [] for name, _ in variants}
        spp = {name: [] for name, _ in variants}
        for rep in range(a.repeats):
            for name, flags in variants:
                out = os.path.join(a.work, "eq-%s-%d.exr" % (name, rep))
                run([a.nusselt, "render", scene, "-o", out, "--time", str(a.time), "--seed", str(rep + 1)] + common +
                    extra + flags)
                errors[name].append(rel_mse(a.nusselt, out, ref))
                spp[name].append(int(info_value(a.nusselt, out, "nusselt/spp")))
        return errors, spp

    # ---- 1. Environment importance sampling + MIS against BSDF sampling alone, equal time ----
    env = ["--env", sun]
    if not a.only_speed:
        ref = reference(env_scene, env, "env")
        errors, spp = equal_time(env_scene, env, ref, [("mis", ["--lighting", "mis"]), ("bsdf", ["--lighting", "bsdf"])])
        print("\n1. equal time (%g s, %dx%d, max depth 4), env_bench.gltf + sun.hdr, %d repeats" %
              (a.time, a.width, a.height, a.repeats))
        print("%-6s %12s %24s %10s" % ("light", "median spp", "relMSE each", "median"))
        for name in errors:
            print("%-6s %12g %24s %10.4g" % (name, statistics.median(spp[name]),
                                             " ".join("%.3g" % e for e in errors[name]), statistics.median(errors[name])))
        print("relMSE ratio bsdf / mis: %.1fx (goal >= 10x)" %
              (statistics.median(errors["bsdf"]) / statistics.median(errors["mis"])))

    # ---- 2. Speed: environment against an area light, equal spp. The machine is shared, so the
    # measure is CPU time (lavapipe renders on the process's own threads): the CPU seconds of a
    # render of 3 N spp minus those of N spp (set-up and compile cancel), for 2 N spp of work. ----
    def cpu_seconds(cmd):
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        run(cmd)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)

    rates = {"environment": [], "area light": []}
    n = a.speed_spp
    for rep in range(a.repeats):
        for name, scene, extra in (("environment", env_scene, env), ("area light", area_scene, ["--env", "none"])):
            out = os.path.join(a.work, "speed.exr")
            base = [a.nusselt, "render", scene, "-o", out, "--width", str(a.width), "--height", str(a.height), "-q",
                    "--checkpoint", "0", "--max-depth", "4"] + extra
            t1 = cpu_seconds(base + ["--spp", str(n)])
            t3 = cpu_seconds(base + ["--spp", str(3 * n)])
            rates[name].append(2 * n * a.width * a.height / max(t3 - t1, 1e-9))
    print("\n2. speed: samples per CPU second (renders of %d and %d spp, the difference; max depth 4; %d repeats)" %
          (n, 3 * n, a.repeats))
    for name, r in rates.items():
        print("%-12s median %.0f samples/CPU s (%s)" % (name, statistics.median(r), " ".join("%.0f" % x for x in r)))
    ratio = statistics.median(rates["environment"]) / statistics.median(rates["area light"])
    print("environment / area light: %.2f (goal: >= 0.85)" % ratio)
    if a.only_speed:
        return

    # ---- 3. Light selection with an area light and the environment ----
    ref2 = reference(area_scene, env, "both")
    errors, spp = equal_time(area_scene, env, ref2, [("half", ["--env-select", "half"]),
                                                     ("power", ["--env-select", "power"])])
    print("\n3. env_bench_area.gltf + sun.hdr: --env-select at equal time (%g s)" % a.time)
    for name in errors:
        print("%-6s median spp %g, relMSE %s, median %.4g" % (name, statistics.median(spp[name]),
                                                              " ".join("%.3g" % e for e in errors[name]),
                                                              statistics.median(errors[name])))
    print("load average at end: %.2f %.2f %.2f" % os.getloadavg())


if __name__ == "__main__":
    main()
