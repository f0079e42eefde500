#!/usr/bin/env python3
"""Load on ftd's web server (--http), measured from outside on the real binary.

soak: two paced ftds side by side, one serving N polling clients (GET /api/v1/state and
      /api/v1/wrench in turn, 10 Hz each) and M event streams, the other none, for S seconds:
      errors, late samples of both over the same window, RSS of the loaded one. Over the same
      window cyclictest (rt-tests; a SCHED_FIFO thread at ftd's priority waking once per sample
      period) counts the wake-ups the host itself delivered more than one period late: the
      platform's share of late samples, measured by a tool that is not ftd.
cpu:  two ftds at RATE Hz side by side, one with K streams open, the other without: whole-process
      CPU (utime + stime from /proc) over the same windows, REPS repetitions, in % of one core.

Usage: bench/web_load.py soak FTD [--pollers 50] [--streams 10] [--seconds 60]
       bench/web_load.py cpu FTD [--rate 8000] [--streams 5] [--reps 5] [--window 10]
"""
import argparse
import http.client
import json
import os
import re
import shutil
import statistics
import subprocess
import tempfile
import threading
import time


def start_ftd(ftd, rate, tmp, name):
    err = open(os.path.join(tmp, name + ".err"), "w+")
    p = subprocess.Popen([ftd, "--adc", "sim", "--rate-hz", str(rate), "--print-hz", "0",
                          "--modbus-tcp", "127.0.0.1:0", "--http", "127.0.0.1:0"],
                         stdout=subprocess.DEVNULL, stderr=err)
    for _ in range(300):
        err.seek(0)
        m = re.search(r"serving the web page on [^:]+:(\d+)", err.read())
        if m:
            return p, int(m.group(1))
        time.sleep(0.05)
    p.kill()
    raise SystemExit(f"{name}: ftd did not announce its web port")


def get_json(port, path):
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=5)
    c.request("GET", path)
    r = c.getresponse()
    body = r.read()
    c.close()
    return json.loads(body)


def ticks(pid):
    f = open(f"/proc/{pid}/stat").read().rsplit(")", 1)[1].split()
    return int(f[11]) + int(f[12])  # utime, stime (fields 14 and 15)


def rss_kb(pid):
    for line in open(f"/proc/{pid}/status"):
        if line.startswith("VmRSS:"):
            return int(line.split()[1])
    return -1


class Load:
    """Pollers and streams against one port until stop() ."""

    def __init__(self, port, pollers, streams, stream_hz=10):
        self.port, self.stop_flag = port, threading.Event()
        self.requests = self.errors = self.events = 0
        self.lock = threading.Lock()
        self.threads = [threading.Thread(target=self.poll, daemon=True) for _ in range(pollers)]
        self.threads += [threading.Thread(target=self.stream, args=(stream_hz,), daemon=True)
                         for _ in range(streams)]
        for t in self.threads:
            t.start()

    def count(self, ok, n=1):
        with self.lock:
            if ok:
                self.requests += n
            else:
                self.errors += 1

    def poll(self):
        c = http.client.HTTPConnection("127.0.0.1", self.port, timeout=5)
        paths = ["/api/v1/state", "/api/v1/wrench"]
        i = 0
        while not self.stop_flag.is_set():
            try:
                c.request("GET", paths[i % 2])
                r = c.getresponse()
                json.loads(r.read())
                self.count(r.status == 200)
            except Exception:
                self.count(False)
                c.close()
                c = http.client.HTTPConnection("127.0.0.1", self.port, timeout=5)
            i += 1
            self.stop_flag.wait(0.1)
        c.close()

    def stream(self, hz):
        try:
            c = http.client.HTTPConnection("127.0.0.1", self.port, timeout=5)
            c.request("GET", f"/api/v1/stream?rate_hz={hz}")
            r = c.getresponse()
            if r.status != 200:
                self.count(False)
                return
            while not self.stop_flag.is_set():
                line = r.fp.readline()
                if not line:
                    self.count(False)
                    return
                if line.startswith(b"data: "):
                    json.loads(line[6:])
                    with self.lock:
                        self.events += 1
            c.close()
        except Exception:
            self.count(False)

    def stop(self):
        self.stop_flag.set()
        for t in self.threads:
            t.join(timeout=10)


def start_cyclictest(rate, seconds, tmp):
    """cyclictest at ftd's sampling priority and period, histogram in µs; None if not installed."""
    if shutil.which("cyclictest") is None:
        return None, None
    hist = os.path.join(tmp, "cyclictest.hist")
    period_us = max(1, round(1e6 / rate))
    p = subprocess.Popen(["cyclictest", "-m", "-q", "-p", "50", "-t", "1", "-i", str(period_us),
                          "-D", str(int(seconds)), "-h", "200000", f"--histfile={hist}"],
                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return p, hist


def host_late_wakeups(proc, hist, rate):
    """(wake-ups later than one period, worst latency µs) from cyclictest's histogram."""
    if proc is None:
        return None
    proc.wait(timeout=60)
    period_us = 1e6 / rate
    late, worst = 0, None
    for line in open(hist):
        if line.startswith("# Max Latencies:"):
            worst = int(line.split(":")[1])
        elif not line.startswith("#") and line.strip():
            us, n = (int(x) for x in line.split()[:2])
            late += n if us > period_us else 0
    return late, worst


def soak(a):
    with tempfile.TemporaryDirectory() as tmp:
        loaded, lport = start_ftd(a.ftd, a.rate, tmp, "loaded")
        idle, iport = start_ftd(a.ftd, a.rate, tmp, "idle")
        try:
            time.sleep(2)
            load = Load(lport, a.pollers, a.streams)
            time.sleep(2)  # clients connected: the window starts in the steady state
            late0 = [get_json(p, "/api/v1/runtime")["late_samples"] for p in (lport, iport)]
            ct, hist = start_cyclictest(a.rate, a.seconds, tmp)
            rss = []
            t0 = time.time()
            while time.time() - t0 < a.seconds:
                rss.append(rss_kb(loaded.pid))
                time.sleep(min(5, a.seconds / 12))
            late1 = [get_json(p, "/api/v1/runtime")["late_samples"] for p in (lport, iport)]
            alive = loaded.poll() is None
            host = host_late_wakeups(ct, hist, a.rate)
            load.stop()
            rss.append(rss_kb(loaded.pid))
        finally:
            for p in (loaded, idle):
                p.terminate()
                p.wait()
    half = len(rss) // 2
    print(f"soak {a.seconds} s at {a.rate} Hz: {a.pollers} pollers (10 Hz each), {a.streams} "
          f"streams (10 Hz): {load.requests} requests, {load.events} stream events, "
          f"{load.errors} errors, ftd alive: {alive}")
    print(f"  late samples in the window: loaded ftd {late1[0] - late0[0]}, idle ftd beside it "
          f"{late1[1] - late0[1]}")
    if host is not None:
        print(f"  host reference (cyclictest, SCHED_FIFO 50, one wake-up per period): {host[0]} "
              f"wake-ups more than one period late, worst {host[1]} µs")
    print(f"  RSS of the loaded ftd, kB: first {rss[0]}, max {max(rss)}, last {rss[-1]} "
          f"(mean of first half {statistics.mean(rss[:half]):.0f}, second "
          f"{statistics.mean(rss[half:]):.0f})  (load average {os.getloadavg()[0]:.1f})")
    return 0 if load.errors == 0 and alive else 1


def cpu(a):
    hz = os.sysconf("SC_CLK_TCK")
    with_s, without_s = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for rep in range(a.reps):
            s_ftd, s_port = start_ftd(a.ftd, a.rate, tmp, "streams")
            n_ftd, _ = start_ftd(a.ftd, a.rate, tmp, "none")
            load = Load(s_port, 0, a.streams)
            time.sleep(2)
            t0, s0, n0 = time.time(), ticks(s_ftd.pid), ticks(n_ftd.pid)
            time.sleep(a.window)
            t1, s1, n1 = time.time(), ticks(s_ftd.pid), ticks(n_ftd.pid)
            events, errors = load.events, load.errors
            load.stop()
            for p in (s_ftd, n_ftd):
                p.terminate()
                p.wait()
            w = 100 * (s1 - s0) / hz / (t1 - t0)
            n = 100 * (n1 - n0) / hz / (t1 - t0)
            with_s.append(w)
            without_s.append(n)
            print(f"  rep {rep + 1}/{a.reps} at {a.rate} Hz over {a.window} s: {a.streams} streams "
                  f"{w:.2f} %, none {n:.2f} %, difference {w - n:+.2f} % ({events} events, "
                  f"{errors} errors; load average {os.getloadavg()[0]:.1f})")
    d = [w - n for w, n in zip(with_s, without_s)]
    print(f"ftd CPU at {a.rate} Hz, % of one core: {a.streams} streams median "
          f"{statistics.median(with_s):.2f}, none {statistics.median(without_s):.2f}; "
          f"difference median {statistics.median(d):+.2f} (range {min(d):+.2f} … {max(d):+.2f}), "
          f"ratio {statistics.median(with_s) / statistics.median(without_s):.2f}")
    return 0


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("mode", choices=["soak", "cpu"])
    ap.add_argument("ftd")
    ap.add_argument("--rate", type=int, default=None)
    ap.add_argument("--pollers", type=int, default=50)
    ap.add_argument("--streams", type=int, default=None)
    ap.add_argument("--seconds", type=float, default=60)
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--window", type=float, default=10)
    a = ap.parse_args()
    if a.mode == "soak":
        a.rate = a.rate or 1000
        a.streams = 10 if a.streams is None else a.streams
        return soak(a)
    a.rate = a.rate or 8000
    a.streams = 5 if a.streams is None else a.streams
    return cpu(a)


if __name__ == "__main__":
    raise SystemExit(main())
