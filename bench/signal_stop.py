#!/usr/bin/python3
"""Time from a signal to the end of a globemesh run, at given times into it, and what it left.

usage: bench/signal_stop.py SIGNALS T1 [T2 ...] -- MESH ARGS (outputs named relative: each run
       gets a fresh folder under $TMPDIR and runs in it)
SIGNALS: INT, TERM, INT2 (SIGINT twice, $GAP s apart, default 0.05)
$G: the executable (default build/release/src/globemesh). Prints, per time: seconds from the
signal to the exit, the status (negative: ended by that signal), the last stage (--verbose is
added), the files left in the folder, and the last line on stderr.
"""
import os, re, shutil, signal, subprocess, sys, tempfile, time

exe = os.environ.get("G", "build/release/src/globemesh")
split = sys.argv.index("--")
kind, times, args = sys.argv[1], [float(t) for t in sys.argv[2:split]], sys.argv[split + 1:]
signals = {"INT": [signal.SIGINT], "TERM": [signal.SIGTERM], "INT2": [signal.SIGINT, signal.SIGINT]}[kind]
for t in times:
    folder = tempfile.mkdtemp(prefix="signal_stop.")
    with tempfile.TemporaryFile("w+") as err:
        run = subprocess.Popen([os.path.abspath(exe)] + args + ["--verbose"], cwd=folder,
                               stdout=subprocess.DEVNULL, stderr=err)
        time.sleep(t)
        sent = time.monotonic()
        for k, s in enumerate(signals):
            if k:
                time.sleep(float(os.environ.get("GAP", "0.05")))
            run.send_signal(s)
        status = run.wait()
        stop_s = time.monotonic() - sent
        err.seek(0)
        text = err.read()
    stages = re.findall(r"\[([^\]]+)\]", text)
    last = text.strip().splitlines()[-1] if text.strip() else ""
    print(f"t={t:5.1f}s {kind:5s} stopped in {stop_s:5.2f}s status {status:4d} "
          f"stage {stages[-1] if stages else '?':24s} left {sorted(os.listdir(folder))} | {last[-60:]}")
    shutil.rmtree(folder)
