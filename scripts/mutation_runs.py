"""What scripts/mutate-meshes.py and scripts/mutate-rigs.py share: their command line, the
contract each run of a tool must keep, and the runs themselves."""
import argparse
import os
import random
import resource
import shutil
import subprocess

# The memory a run may take: far past what these small inputs need.
MEMORY = 4 << 30


def arguments(doc, more=None):
    """BUILD_DIR DATA_DIR OUT_DIR [--runs N] [--seed S] [--timeout SECONDS]; OUT_DIR made afresh.
    `more(parser)` adds a script's own options."""
    ap = argparse.ArgumentParser(description=doc.split("\n")[0])
    if more:
        more(ap)
    ap.add_argument("build")
    ap.add_argument("data")
    ap.add_argument("out")
    ap.add_argument("--runs", type=int, default=200)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--timeout", type=float, default=60)
    a = ap.parse_args()
    a.build, a.out = os.path.abspath(a.build), os.path.abspath(a.out)
    shutil.rmtree(a.out, ignore_errors=True)
    os.makedirs(a.out)
    return a


def broken_contract(command, output, timeout, warner=None):
    """Runs `command`, which writes the file `output`: None where it ended as it should (exit 0 with
    `output` written and nothing said but, where `warner` names the tool, its warnings; or exit 1-3
    with one `Error:` line and no `output`, not for want of memory), else what was wrong."""
    if os.path.exists(output):
        os.remove(output)
    # A reader that runs away allocates without end (assimp's COLLADA reader took 6 GB in 15 s on a
    # damaged 21 KB file): the limit ends it before the machine runs out, and says so below.
    # (Not under the sanitizers, SPX_SANITIZED: ASan reserves terabytes of address space at start.)
    limit = lambda: resource.setrlimit(resource.RLIMIT_AS, (MEMORY, MEMORY))
    sanitized = bool(os.environ.get("SPX_SANITIZED"))
    try:
        r = subprocess.run(command, capture_output=True, timeout=timeout, preexec_fn=None if sanitized else limit)
    except subprocess.TimeoutExpired:
        return "no end within %g s" % timeout
    err = [line for line in r.stderr.decode(errors="replace").splitlines() if line.strip()]
    if any("out of memory" in line for line in err):
        return "out of memory within %d GiB: %s" % (MEMORY >> 30, " | ".join(err)[-300:])
    written = os.path.exists(output)
    if r.returncode == 0 and warner:
        err = [line for line in err if not line.startswith(warner + ": warning: ")]
    if r.returncode == 0:
        return None if written and not err else "exit 0 with %s" % ("lines: " + " | ".join(err) if err else "nothing written")
    if r.returncode not in (1, 2, 3):
        return "exit %d: %s" % (r.returncode, " | ".join(err)[-300:])
    if len(err) != 1 or not err[0].startswith("Error: "):
        return "exit %d with %d lines: %s" % (r.returncode, len(err), " | ".join(err)[-300:])
    return "exit %d but %s written" % (r.returncode, os.path.basename(output)) if written else None


def run_all(name, a, next_input, command, warner=None):
    """a.runs runs from random.Random(a.seed): next_input(rng) gives (extension, bytes, what was
    changed), written to OUT/in.EXT; command(path) gives the tool's command line and its output.
    A run that breaks the contract keeps its input as OUT/failed-RUN.EXT. Returns the exit code."""
    rng = random.Random(a.seed)
    failed = []
    for run in range(a.runs):
        ext, data, said = next_input(rng)
        path = "%s/in.%s" % (a.out, ext)
        with open(path, "wb") as f:
            f.write(data)
        wrong = broken_contract(*command(path), a.timeout, warner)
        if wrong:
            kept = "%s/failed-%d.%s" % (a.out, run, ext)
            shutil.copy(path, kept)
            failed.append(kept)
            print("FAIL %s%s: %s" % (kept, " (%s)" % said if said else "", wrong), flush=True)
    print("%s: %d runs, %d passed, %d failed" % (name, a.runs, a.runs - len(failed), len(failed)))
    return 1 if failed else 0
