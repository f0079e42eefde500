#!/usr/bin/python3
"""Fleet benchmark (bench/run.sh): N simulated ftd publishing Sparkplug B to one local mosquitto.

For each N: wrench messages per second delivered to one subscriber, end-to-end latency (from the
last sample of a window, Wrench/Time_us, to the subscriber's receive time) p50/p99, messages lost
(gaps in each device's seq) and dropped (ftd's own counter), CPU per ftd; then the same N without
--mqtt, and the late-sample counters of both runs side by side.

  FTD=build/bin/ftd SPARKPLUG_PY_DIR=build/python bench/mqtt_fleet.py [N ...]
Environment: FLEET_SECONDS (measured seconds per run, default 6), FLEET_RATE_HZ (sample rate of
each simulated sensor, default 500), FLEET_MQTT_HZ (wrench publications per second, default 10)."""
import os
import re
import signal
import subprocess
import sys
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "tests", "system"))
from mqtt_fixture import Broker, TempDir  # noqa: E402
import sparkplug_host  # noqa: E402

SECONDS = float(os.environ.get("FLEET_SECONDS", "6"))
RATE_HZ = int(os.environ.get("FLEET_RATE_HZ", "500"))
MQTT_HZ = float(os.environ.get("FLEET_MQTT_HZ", "10"))
TICK = os.sysconf("SC_CLK_TCK")


def cpu_s(pid):
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / TICK


class Counter:
    """Counts DDATA per device inside the measured interval; latency and seq gaps."""

    def __init__(self):
        self.lock = threading.Lock()
        self.measuring = False
        self.count = 0
        self.latencies_ms = []
        self.last_seq = {}
        self.lost = 0
        self.dropped = {}  # device -> MQTT/Dropped as last reported (births and by exception)

    def on_message(self, client, userdata, msg):
        now_us = time.time() * 1e6
        parts = msg.topic.split("/")
        if len(parts) < 5 or parts[2] not in ("DBIRTH", "DDATA"):
            return
        p = sparkplug_host.sparkplug_b_pb2.Payload()
        p.ParseFromString(msg.payload)
        dropped = next((m.long_value for m in p.metrics if m.name == "MQTT/Dropped"), None)
        if dropped is not None:
            with self.lock:
                self.dropped[parts[3]] = dropped
        if parts[2] != "DDATA":
            return
        t_us = next((m.long_value for m in p.metrics if m.name == "Wrench/Time_us"), None)
        key = parts[3]
        with self.lock:
            prev = self.last_seq.get(key)
            if prev is not None and self.measuring:
                self.lost += (p.seq - prev - 1) % 256
            self.last_seq[key] = p.seq
            if self.measuring:
                self.count += 1
                if t_us:
                    self.latencies_ms.append((now_us - t_us) / 1000.0)


def pct(values, q):
    if not values:
        return float("nan")
    v = sorted(values)
    return v[min(len(v) - 1, int(round(q * (len(v) - 1))))]


def run_fleet(tmp, broker, n, mqtt):
    counter = Counter()
    client = None
    if mqtt:
        import paho.mqtt.client as paho
        client = paho.Client(client_id=f"fleet-{os.getpid()}-{n}")
        client.on_message = counter.on_message
        client.connect("127.0.0.1", broker.port)
        client.subscribe("spBv1.0/fleet/DDATA/#", qos=0)
        client.loop_start()
    procs = []
    for i in range(n):
        args = [os.environ["FTD"], "--adc", "sim", "--rate-hz", str(RATE_HZ), "--seed", str(i + 1),
                "--print-hz", "0"]
        if mqtt:
            args += ["--mqtt", f"mqtt://127.0.0.1:{broker.port}", "--sparkplug-group", "fleet",
                     "--edge-node", f"node{i}", "--device", "ft", "--mqtt-rate-hz", str(MQTT_HZ)]
        err = open(os.path.join(tmp, f"ftd{i}.{'on' if mqtt else 'off'}.stderr"), "w")
        procs.append((subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=err), err))
    time.sleep(1.5)  # start-up and births
    cpu0 = [cpu_s(p.pid) for p, _ in procs]
    with counter.lock:
        counter.measuring = True
        dropped0 = sum(counter.dropped.values())
    t0 = time.time()
    time.sleep(SECONDS)  # the windows of the interval's last 0.1 s report their drops
    with counter.lock:
        counter.measuring = False
        dropped = sum(counter.dropped.values()) - dropped0
    wall = time.time() - t0
    cpu1 = [cpu_s(p.pid) for p, _ in procs]
    late = 0
    for p, err in procs:
        p.send_signal(signal.SIGTERM)
        p.wait(20)
        err.close()
        text = open(err.name).read()
        m = re.search(r", (\d+) late", text)
        late += int(m.group(1)) if m else 0
    if client:
        client.loop_stop()
        client.disconnect()
    cpu = [(b - a) / wall * 100 for a, b in zip(cpu0, cpu1)]
    return {"msgs_s": counter.count / wall, "expected_s": n * MQTT_HZ,
            "p50": pct(counter.latencies_ms, 0.5), "p99": pct(counter.latencies_ms, 0.99),
            "lost": counter.lost, "dropped": dropped, "cpu_mean": sum(cpu) / len(cpu),
            "cpu_max": max(cpu), "late": late}


def main():
    sizes = [int(a) for a in sys.argv[1:]] or [1, 10, 50]
    tmp = TempDir()
    broker = Broker(tmp.path)
    try:
        print(f"  {RATE_HZ} Hz simulated sensors, wrench means published at {MQTT_HZ:g} Hz each, "
              f"{SECONDS:g} s measured per run, one mosquitto on 127.0.0.1")
        print(f"  {'N':>3} {'msgs/s':>8} {'expected':>8} {'p50 ms':>7} {'p99 ms':>7} {'lost':>5} "
              f"{'dropped':>7} {'CPU/ftd %':>10} {'max %':>6} | {'late (MQTT on)':>14} "
              f"{'late (off)':>10} {'CPU off %':>9}")
        for n in sizes:
            on = run_fleet(tmp.path, broker, n, True)
            off = run_fleet(tmp.path, broker, n, False)
            print(f"  {n:>3} {on['msgs_s']:>8.1f} {on['expected_s']:>8.1f} {on['p50']:>7.2f} "
                  f"{on['p99']:>7.2f} {on['lost']:>5} {on['dropped']:>7} {on['cpu_mean']:>10.2f} "
                  f"{on['cpu_max']:>6.2f} | {on['late']:>14} {off['late']:>10} "
                  f"{off['cpu_mean']:>9.2f}", flush=True)
    finally:
        broker.stop()
        tmp.cleanup()


if __name__ == "__main__":
    main()
