#!/usr/bin/python3
"""Fleet benchmark (bench/run.sh): N simulated ftd publishing Sparkplug B to one local mosquitto.

For each N: wrench messages per second delivered to one subscriber, end-to-end latency (from the
last sample of a window, Wrench/Time_us, to the subscriber's receive time) p50/p99, messages lost
(gaps in each device's seq) and dropped (MQTT/Dropped during the interval), CPU per ftd; beside
them, at the same time, N more ftd without --mqtt: the late-sample counters (input registers
74-75, read over Modbus at the start and end of the interval) of both fleets under the same load.

  FTD=build/bin/ftd SPARKPLUG_PY_DIR=build/python bench/mqtt_fleet.py [N ...]
Environment: FLEET_SECONDS (measured seconds per run, default 6), FLEET_RATE_HZ (sample rate of
each simulated sensor, default 500), FLEET_MQTT_HZ (wrench publications per second, default 10)."""
import os
import re
import signal
import socket
import struct
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


def start_ftd(tmp, broker, i, mqtt):
    args = [os.environ["FTD"], "--adc", "sim", "--rate-hz", str(RATE_HZ), "--seed", str(i + 1),
            "--print-hz", "0", "--modbus-tcp", "127.0.0.1:0"]
    if mqtt:
        args += ["--mqtt", f"mqtt://127.0.0.1:{broker.port}", "--sparkplug-group", "fleet",
                 "--edge-node", f"node{i}", "--device", "ft", "--mqtt-rate-hz", str(MQTT_HZ)]
    err = open(os.path.join(tmp, f"ftd{i}.{'on' if mqtt else 'off'}.stderr"), "w")
    return subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=err), err


def modbus_port(err, deadline_s=30.0):
    """The port an ftd printed on stderr; under a fleet's start-up load the line may come late."""
    t_end = time.time() + deadline_s
    while True:
        err.flush()
        m = re.search(r"serving Modbus TCP on [\d.]+:(\d+)", open(err.name).read())
        if m:
            return int(m.group(1))
        if time.time() > t_end:
            raise RuntimeError(f"{err.name}: no 'serving Modbus TCP' line after {deadline_s:g} s")
        time.sleep(0.1)


def late_samples(procs):
    """Each ftd's late-sample counter (input registers 74-75) over Modbus TCP, function 04.

    With 2N processes sharing a few cores an ftd's server thread can wait seconds for a core, so
    the read allows 20 s and tries three times before it gives up on that ftd."""
    total = 0
    for p, err in procs:
        port = modbus_port(err)
        for attempt in range(3):
            try:
                with socket.create_connection(("127.0.0.1", port), timeout=20) as c:
                    c.sendall(struct.pack(">HHHBBHH", 1, 0, 6, 1, 4, 74, 2))
                    reply = b""
                    while len(reply) < 13:
                        chunk = c.recv(13 - len(reply))
                        if not chunk:
                            raise ConnectionError("closed before a whole reply")
                        reply += chunk
                break
            except (OSError, ConnectionError) as e:
                if attempt == 2:
                    raise RuntimeError(f"ftd pid {p.pid} (port {port}): late-sample read: {e}")
        if reply[7] != 4:
            raise RuntimeError(f"ftd pid {p.pid}: Modbus exception {reply[7]:#x} reading 74-75")
        total += struct.unpack(">I", reply[9:13])[0]
    return total


def stop_all(procs):
    for p, err in procs:
        p.send_signal(signal.SIGTERM)
    for p, err in procs:
        p.wait(20)
        err.close()


def run_fleet(tmp, broker, n):
    """n ftd with --mqtt and n without, running at the same time (the same load on the machine)."""
    import paho.mqtt.client as paho
    counter = Counter()
    client = paho.Client(client_id=f"fleet-{os.getpid()}-{n}")
    client.on_message = counter.on_message
    client.connect("127.0.0.1", broker.port)
    client.subscribe("spBv1.0/fleet/#", qos=0)
    client.loop_start()
    on, off = [], []
    for i in range(n):  # interleaved, so that start-up loads both fleets alike
        on.append(start_ftd(tmp, broker, i, True))
        off.append(start_ftd(tmp, broker, i, False))
    time.sleep(1.5)  # start-up and births
    late0 = late_samples(on), late_samples(off)
    cpu0 = {p.pid: cpu_s(p.pid) for p, _ in on + off}
    with counter.lock:
        counter.measuring = True
        dropped0 = sum(counter.dropped.values())
    t0 = time.time()
    time.sleep(SECONDS)
    with counter.lock:
        counter.measuring = False
        dropped = sum(counter.dropped.values()) - dropped0
    wall = time.time() - t0
    cpu = {p.pid: (cpu_s(p.pid) - cpu0[p.pid]) / wall * 100 for p, _ in on + off}
    late_on, late_off = late_samples(on) - late0[0], late_samples(off) - late0[1]
    stop_all(on + off)
    client.loop_stop()
    client.disconnect()
    cpu_on = [cpu[p.pid] for p, _ in on]
    cpu_off = [cpu[p.pid] for p, _ in off]
    return {"msgs_s": counter.count / wall, "expected_s": n * MQTT_HZ,
            "p50": pct(counter.latencies_ms, 0.5), "p99": pct(counter.latencies_ms, 0.99),
            "lost": counter.lost, "dropped": dropped, "cpu_mean": sum(cpu_on) / n,
            "cpu_max": max(cpu_on), "cpu_off": sum(cpu_off) / n, "late": late_on,
            "late_off": late_off}


def main():
    sizes = [int(a) for a in sys.argv[1:]] or [1, 10, 50]
    tmp = TempDir()
    broker = Broker(tmp.path)
    try:
        print(f"  {RATE_HZ} Hz simulated sensors, wrench means published at {MQTT_HZ:g} Hz each, "
              f"{SECONDS:g} s measured per run, one mosquitto on 127.0.0.1; N more without MQTT "
              "run at the same time")
        print(f"  {'N':>3} {'msgs/s':>8} {'expected':>8} {'p50 ms':>7} {'p99 ms':>7} {'lost':>5} "
              f"{'dropped':>7} {'CPU/ftd %':>10} {'max %':>6} | {'late (MQTT on)':>14} "
              f"{'late (off)':>10} {'CPU off %':>9}")
        for n in sizes:
            r = run_fleet(tmp.path, broker, n)
            print(f"  {n:>3} {r['msgs_s']:>8.1f} {r['expected_s']:>8.1f} {r['p50']:>7.2f} "
                  f"{r['p99']:>7.2f} {r['lost']:>5} {r['dropped']:>7} {r['cpu_mean']:>10.2f} "
                  f"{r['cpu_max']:>6.2f} | {r['late']:>14} {r['late_off']:>10} "
                  f"{r['cpu_off']:>9.2f}", flush=True)
    finally:
        broker.stop()
        tmp.cleanup()


if __name__ == "__main__":
    main()
