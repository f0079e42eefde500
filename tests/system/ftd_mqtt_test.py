"""ftd --mqtt against a real mosquitto, read by an independent Sparkplug B host (paho-mqtt and the
protoc-generated decoder): births, data, death, seq, bdSeq, rebirth, commands, reconnect, TLS,
credentials. Run one test: FTD=build/bin/ftd SPARKPLUG_PY_DIR=build/python python3 THIS Class.test"""
import csv
import os
import re
import signal
import socket
import subprocess
import sys
import time
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from mqtt_fixture import Broker, Ftd, TempDir, free_port, make_tls_files  # noqa: E402
from sparkplug_host import SparkplugHost, reconstruct, sparkplug_b_pb2 as pb  # noqa: E402

GROUP, NODE, DEVICE = "plant1", "cell7", "ft-test"
APPLIED = [10.0, -20.0, 30.0, 0.5, -0.25, 0.125]
AXES = ["Fx_n", "Fy_n", "Fz_n", "Mx_nm", "My_nm", "Mz_nm"]
DDATA_TOPIC = f"spBv1.0/{GROUP}/DDATA/{NODE}/{DEVICE}"


def ftd_args(port, *extra, scheme="mqtt", rate_hz=20, keepalive_s=5):
    return ["--adc", "sim", "--sim-wrench", ",".join(str(v) for v in APPLIED),
            "--mqtt", f"{scheme}://127.0.0.1:{port}", "--sparkplug-group", GROUP,
            "--edge-node", NODE, "--device", DEVICE, "--mqtt-rate-hz", str(rate_hz),
            "--mqtt-keepalive-s", str(keepalive_s), "--print-hz", "0", *extra]


def mbpoll(port, table, first, count):
    """Input registers read by mbpoll (0-based addresses; '3:int' = uint32 high word first,
    '3:float' = float32 high word first)."""
    out = subprocess.run(["mbpoll", "-m", "tcp", "-p", str(port), "-a", "1", "-t", table, "-B",
                          "-0", "-r", str(first), "-c", str(count), "-1", "127.0.0.1"],
                         capture_output=True, text=True, timeout=10, check=True).stdout
    values = {}
    for line in out.splitlines():
        if line.startswith("["):
            addr, value = line.split(":", 1)
            text = value.strip()
            values[int(addr.strip("[]"))] = float(text) if "float" in table else int(text)
    return values


def check_sequence(test, msgs):
    """seq runs 0 (NBIRTH), 1 (DBIRTH), 2, … mod 256 across every message of one birth."""
    expected = None
    wraps = 0
    for m in msgs:
        if m.kind not in ("NBIRTH", "DBIRTH", "DDATA", "NDEATH"):
            continue  # the host's own commands
        if m.kind == "NDEATH":
            test.assertIsNone(m.seq, "NDEATH carries no seq")
            expected = None
            continue
        if m.kind == "NBIRTH":
            test.assertEqual(m.seq, 0)
        elif expected is not None:
            test.assertEqual(m.seq, expected, f"{m.kind} seq")
            if m.seq == 0:
                wraps += 1
        test.assertLessEqual(m.seq, 255)
        expected = (m.seq + 1) % 256
    return wraps


class MqttTest(unittest.TestCase):
    def setUp(self):
        self.tmp = TempDir()
        self.broker = None
        self.host = None
        self.ftds = []

    def tearDown(self):
        for f in self.ftds:
            f.stop(signal.SIGKILL)
        if self.host:
            self.host.close()
        if self.broker:
            self.broker.stop()
        self.tmp.cleanup()

    def start(self, args, name="ftd"):
        f = Ftd(self.tmp.path, args, name)
        self.ftds.append(f)
        return f

    def test_birth_data_death(self):
        """NBIRTH/DBIRTH with every metric typed, DDATA means equal to the logged samples, the
        will (NDEATH, bdSeq of the birth) within the keep-alive of a killed ftd."""
        self.broker = Broker(self.tmp.path)
        self.host = SparkplugHost(self.broker.port)
        log = os.path.join(self.tmp.path, "samples.csv")
        ftd = self.start(ftd_args(self.broker.port, "--log", log))
        nbirth = self.host.wait_kind("NBIRTH")
        self.assertEqual(nbirth.topic, f"spBv1.0/{GROUP}/NBIRTH/{NODE}")
        self.assertEqual(nbirth.seq, 0)
        self.assertEqual(nbirth.type_name("bdSeq"), "UInt64")
        self.assertEqual(nbirth.type_name("Node Control/Rebirth"), "Boolean")
        self.assertFalse(nbirth.value("Node Control/Rebirth"))
        dbirth = self.host.wait_kind("DBIRTH")
        self.assertEqual(dbirth.topic, f"spBv1.0/{GROUP}/DBIRTH/{NODE}/{DEVICE}")
        self.assertEqual(dbirth.seq, 1)
        expected_types = {f"Wrench/{a}": "Double" for a in AXES} | {
            "Wrench/Samples": "UInt32", "Wrench/Sequence": "UInt32", "Wrench/Time_us": "UInt64",
            "Status/Bits": "UInt16", "Status/Simulated": "Boolean", "Status/Tare Active": "Boolean",
            "Events/Overload Events": "UInt32", "Events/Late Samples": "UInt32",
            "Peaks/Fz_n": "Double", "Config/Calibration CRC": "UInt32",
            "Config/Calibration Slot": "UInt8", "Config/Payload CRC": "UInt32",
            "Config/Tool Transform/Dz_m": "Float", "Config/Decimation": "UInt16",
            "MQTT/Dropped": "UInt64", "MQTT/Reconnects": "UInt32",
            "Device Control/Tare": "Boolean", "Device Control/Clear Peaks": "Boolean",
            "Device Control/Commands": "UInt32", "Device Control/Last Result": "String",
            "Health/State": "UInt8", "Health/Findings": "UInt16", "Health/Coverage": "UInt16"}
        for name, t in expected_types.items():
            self.assertIn(name, dbirth.metrics, name)
            self.assertEqual(dbirth.type_name(name), t, name)
        self.assertTrue(dbirth.value("Status/Simulated"))
        self.assertEqual(dbirth.value("Status/Bits") & 0x80, 0x80)
        data = [self.host.wait_for(lambda m: m.kind == "DDATA", 10, "DDATA") for _ in range(20)]
        # The health watch's coverage (input 196) by exception: a held load, no effect — the
        # tones (bits 2, 3) and the noise (bit 4, after the 5 s commissioning) could be judged.
        covered = self.host.wait_for(
            lambda m: m.kind == "DDATA" and "Health/Coverage" in m.metrics
            and m.value("Health/Coverage") & 0x1C == 0x1C, 15, "Health/Coverage")
        self.assertEqual(covered.value("Health/Coverage") & 0x1C, 0x1C)
        self.assertEqual(dbirth.value("Health/Findings"), 0)
        for m in data:
            self.assertEqual(m.topic, DDATA_TOPIC)
            for a in AXES:
                self.assertEqual(m.type_name(f"Wrench/{a}"), "Double")
        # Each window: 1000 Hz / 20 Hz = 50 samples; its mean equals the mean of the same samples
        # in ftd's own recording (an independent path: the CSV logger), to the LSB's rounding.
        ftd.stop(signal.SIGTERM)
        with open(log) as f:
            rows = [r for r in csv.reader(line for line in f if not line.startswith("#"))]
        header, rows = rows[0], rows[1:]
        # One row per published sample, in order; the first published sample has sequence 1.
        self.assertNotIn("log dropped", ftd.text())
        cols = [header.index(c) for c in ("Fx", "Fy", "Fz", "Mx", "My", "Mz")]
        by_seq = {i + 1: [float(r[c]) for c in cols] for i, r in enumerate(rows)}
        checked = 0
        for m in data:
            n, last = m.value("Wrench/Samples"), m.value("Wrench/Sequence")
            self.assertEqual(n, 50)
            window = [by_seq[s] for s in range(last - n + 1, last + 1) if s in by_seq]
            if len(window) != n:
                continue
            checked += 1
            for k, a in enumerate(AXES):
                mean = sum(w[k] for w in window) / n
                self.assertAlmostEqual(m.value(f"Wrench/{a}"), mean, delta=1e-6, msg=a)
                self.assertAlmostEqual(m.value(f"Wrench/{a}"), APPLIED[k],
                                       delta=0.02 * max(abs(APPLIED[k]), 1.0), msg=a)
        self.assertGreaterEqual(checked, 15)
        # A clean stop publishes NDEATH itself, with the birth's bdSeq.
        death = self.host.wait_kind("NDEATH")
        self.assertEqual(death.value("bdSeq"), nbirth.value("bdSeq"))
        check_sequence(self, self.host.snapshot())
        state = reconstruct(self.host.snapshot(), f"/{NODE}/{DEVICE}")
        self.assertEqual(state["Config/Calibration CRC"], dbirth.value("Config/Calibration CRC"))
        self.assertAlmostEqual(state["Wrench/Fz_n"], APPLIED[2], delta=0.6)

        # A killed ftd: the broker publishes the will within 1.5 x the keep-alive (5 s here).
        ftd2 = self.start(ftd_args(self.broker.port), "ftd2")
        nbirth2 = self.host.wait_kind("NBIRTH")
        self.host.wait_kind("DDATA")
        killed = time.time()
        ftd2.stop(signal.SIGKILL)
        death2 = self.host.wait_kind("NDEATH", timeout_s=8)
        self.assertLess(death2.received_s - killed, 7.5)
        self.assertEqual(death2.value("bdSeq"), nbirth2.value("bdSeq"))
        self.assertEqual(death2.type_name("bdSeq"), "UInt64")

    def test_rebirth_and_seq_wrap(self):
        """Node Control/Rebirth: a new NBIRTH (seq 0, same bdSeq) and DBIRTH; seq wraps 255 -> 0."""
        self.broker = Broker(self.tmp.path)
        self.host = SparkplugHost(self.broker.port)
        self.start(ftd_args(self.broker.port, rate_hz=200))
        nbirth = self.host.wait_kind("NBIRTH")
        self.host.wait_for(lambda m: m.kind == "DDATA" and m.seq == 255, 10, "DDATA seq 255")
        wrapped = self.host.wait_kind("DDATA")
        self.assertEqual(wrapped.seq, 0)
        self.host.publish_command(f"spBv1.0/{GROUP}/NCMD/{NODE}",
                                  [("Node Control/Rebirth", pb.Boolean, True)])
        rebirth = self.host.wait_kind("NBIRTH")
        self.assertEqual(rebirth.seq, 0)
        self.assertEqual(rebirth.value("bdSeq"), nbirth.value("bdSeq"))
        self.assertEqual(self.host.wait_kind("DBIRTH").seq, 1)
        self.assertEqual(self.host.wait_kind("DDATA").seq, 2)
        self.assertGreaterEqual(check_sequence(self, self.host.snapshot()), 1)

    def test_default_names(self):
        """Without --sparkplug-group/--edge-node/--device: group ftstack, the host name, and (no
        calibration file) ft- and the active calibration's CRC-32 in hex."""
        self.broker = Broker(self.tmp.path)
        self.host = SparkplugHost(self.broker.port)
        self.start(["--adc", "sim", "--mqtt", f"mqtt://127.0.0.1:{self.broker.port}",
                    "--print-hz", "0"])
        host = socket.gethostname()
        for c in "/+# ":
            host = host.replace(c, "_")
        nbirth = self.host.wait_kind("NBIRTH")
        self.assertEqual(nbirth.topic, f"spBv1.0/ftstack/NBIRTH/{host}")
        dbirth = self.host.wait_kind("DBIRTH")
        crc = dbirth.value("Config/Calibration CRC")
        self.assertNotEqual(crc, 0)
        self.assertEqual(dbirth.topic, f"spBv1.0/ftstack/DBIRTH/{host}/ft-{crc:08x}")

    def command(self, name):
        self.host.publish_command(f"spBv1.0/{GROUP}/DCMD/{NODE}/{DEVICE}",
                                  [(name, pb.Boolean, True)])
        return self.host.wait_for(
            lambda m: m.kind == "DDATA" and "Device Control/Commands" in m.metrics, 5, "ack")

    def test_commands_and_write_protect(self):
        """Tare and clear peaks, acknowledged in the next DDATA; the tare enters the tare history
        (input 210-229) as source 3 with the load it removed; anything else and everything under
        --mqtt-write-protect is refused and changes nothing."""
        self.broker = Broker(self.tmp.path)
        self.host = SparkplugHost(self.broker.port)
        modbus = free_port()
        self.start(ftd_args(self.broker.port, "--modbus-tcp", f"127.0.0.1:{modbus}"))
        self.host.wait_kind("DBIRTH")
        ack = self.command("Device Control/Tare")
        self.assertEqual(ack.value("Device Control/Commands"), 1)
        self.assertEqual(ack.value("Device Control/Last Command"), "Device Control/Tare")
        self.assertEqual(ack.value("Device Control/Last Result"), "accepted")
        tared = self.host.wait_for(lambda m: m.kind == "DDATA" and m.metrics.get("Status/Tare Active")
                                   is not None and m.value("Status/Tare Active"), 5, "tare bit")
        later = [self.host.wait_kind("DDATA") for _ in range(3)][-1]
        for k, a in enumerate(AXES):
            self.assertLess(abs(later.value(f"Wrench/{a}")), 0.02 * max(abs(APPLIED[k]), 1.0), a)
        self.assertIsNotNone(tared)
        # The newest tare of the history: number 1, asked over MQTT (3), at the constant
        # --sim-wrench's 20 °C, and the load it removed is the applied one.
        self.assertEqual(mbpoll(modbus, "3:int", 210, 1)[210], 1)
        self.assertEqual(mbpoll(modbus, "3", 212, 1)[212], 3)
        self.assertAlmostEqual(mbpoll(modbus, "3:float", 216, 1)[216], 20.0, delta=0.01)
        removed = mbpoll(modbus, "3:float", 218, 6)
        for k, a in enumerate(AXES):
            self.assertAlmostEqual(removed[218 + 2 * k], APPLIED[k],
                                   delta=0.02 * max(abs(APPLIED[k]), 1.0), msg=a)
        self.assertEqual(mbpoll(modbus, "3:int", 230, 1)[230], 0)  # no second tare
        ack = self.command("Device Control/Clear Peaks")
        self.assertEqual(ack.value("Device Control/Commands"), 2)
        self.assertEqual(ack.value("Device Control/Last Result"), "accepted")
        ack = self.command("Device Control/Calibration Slot")
        self.assertEqual(ack.value("Device Control/Commands"), 3)
        self.assertTrue(ack.value("Device Control/Last Result").startswith("refused"))
        self.ftds[0].stop()
        self.host.wait_kind("NDEATH")

        protected = self.start(ftd_args(self.broker.port, "--mqtt-write-protect"), "ftd-wp")
        birth = self.host.wait_kind("DBIRTH")
        self.assertTrue(birth.value("Device Control/Write Protected"))
        ack = self.command("Device Control/Tare")
        self.assertEqual(ack.value("Device Control/Last Result"), "refused: write-protected")
        later = [self.host.wait_kind("DDATA") for _ in range(3)][-1]
        self.assertAlmostEqual(later.value("Wrench/Fz_n"), APPLIED[2], delta=0.6)
        protected.stop()

    def test_reconnect_after_broker_restart(self):
        """The broker restarts on the same port: ftd reconnects with back-off, bdSeq + 1 or more,
        NBIRTH and DBIRTH again before any DDATA, MQTT/Reconnects counts it."""
        self.broker = Broker(self.tmp.path)
        self.host = SparkplugHost(self.broker.port)
        modbus = free_port()
        ftd = self.start(ftd_args(self.broker.port, "--modbus-tcp", f"127.0.0.1:{modbus}"))
        first = self.host.wait_kind("NBIRTH")
        self.host.wait_kind("DDATA")
        self.host.close()
        self.broker.stop()
        time.sleep(1.0)
        self.broker.start()
        self.host = SparkplugHost(self.broker.port)
        second = self.host.wait_kind("NBIRTH", timeout_s=15)
        self.assertGreater(second.value("bdSeq"), first.value("bdSeq"))
        dbirth = self.host.wait_kind("DBIRTH")
        self.assertGreaterEqual(dbirth.value("MQTT/Reconnects"), 1)
        self.assertGreater(dbirth.value("MQTT/Dropped"), 0)  # windows while the broker was away
        self.host.wait_kind("DDATA")
        kinds = [m.kind for m in self.host.snapshot()]
        self.assertEqual(kinds[:2], ["NBIRTH", "DBIRTH"])
        check_sequence(self, self.host.snapshot())
        self.assertEqual(ftd.proc.poll(), None)
        # Input registers 200-206 (map v3) read by mbpoll: connected, published, dropped,
        # reconnects, the same counters the Sparkplug metrics carry.
        connected = mbpoll(modbus, "3", 200, 1)[200]
        counters = mbpoll(modbus, "3:int", 201, 3)
        self.assertEqual(connected, 1)
        self.assertGreater(counters[201], 3)
        self.assertGreaterEqual(counters[203], dbirth.value("MQTT/Dropped"))
        self.assertEqual(counters[205], dbirth.value("MQTT/Reconnects"))

    def test_stalled_broker_does_not_slow_sampling(self):
        """The broker stops reading (SIGSTOP) for 2.5 s: ftd keeps sampling at its rate, and the
        data flows again when the broker resumes."""
        self.broker = Broker(self.tmp.path)
        self.host = SparkplugHost(self.broker.port)
        ftd = self.start(ftd_args(self.broker.port, "--duration-s", "5", rate_hz=100))
        self.host.wait_kind("DBIRTH")
        self.broker.proc.send_signal(signal.SIGSTOP)
        time.sleep(2.5)
        self.broker.proc.send_signal(signal.SIGCONT)
        resumed = time.time()
        m = self.host.wait_for(lambda x: x.kind == "DDATA" and x.received_s > resumed + 0.5, 5,
                               "DDATA after the stall")
        self.assertEqual(m.value("Wrench/Samples"), 10)
        self.assertEqual(ftd.proc.wait(15), 0)
        summary = re.search(r"(\d+) samples in ([\d.]+) s \((\d+) Hz\)", ftd.text())
        self.assertIsNotNone(summary, ftd.text())
        rate = int(summary.group(1)) / float(summary.group(2))
        self.assertAlmostEqual(rate, 1000, delta=20, msg=ftd.text())

    def test_tls_with_self_signed_ca(self):
        """mqtts:// with a CA generated here; without that CA the connection is refused."""
        tls = make_tls_files(self.tmp.path)
        self.broker = Broker(self.tmp.path, tls=tls)
        self.host = SparkplugHost(self.broker.port, tls_ca=tls["ca"])
        ftd = self.start(ftd_args(self.broker.port, "--mqtt-ca", tls["ca"], scheme="mqtts"))
        self.assertEqual(self.host.wait_kind("NBIRTH").seq, 0)
        self.host.wait_kind("DDATA")
        ftd.stop()
        self.host.wait_kind("NDEATH")
        # Another CA: the handshake fails, ftd keeps retrying and never births.
        other = os.path.join(self.tmp.path, "other")
        os.mkdir(other)
        wrong = make_tls_files(other)["ca"]
        bad = self.start(ftd_args(self.broker.port, "--mqtt-ca", wrong, scheme="mqtts"), "bad")
        time.sleep(2)
        self.assertEqual(bad.proc.poll(), None)
        self.assertNotIn("NBIRTH", [m.kind for m in self.host.snapshot()[3:]])
        bad.stop()

    def test_credentials_file_and_bad_options(self):
        """User and password from a file only; a URL with credentials, a bad scheme or a bad name
        is refused at start (exit 2, one line)."""
        pw = os.path.join(self.tmp.path, "passwd")
        with open(pw, "w"):
            pass
        subprocess.run(["mosquitto_passwd", "-b", pw, "sensor", "s3cret"], check=True)
        os.chmod(pw, 0o600)
        self.broker = Broker(self.tmp.path, password_file=pw)
        cred = os.path.join(self.tmp.path, "cred")
        with open(cred, "w") as f:
            f.write("sensor\ns3cret\n")
        os.chmod(cred, 0o600)
        wrong = os.path.join(self.tmp.path, "wrong")
        with open(wrong, "w") as f:
            f.write("sensor\nnope\n")
        # The host authenticates too (the broker allows no anonymous client).
        self.host = SparkplugHost(self.broker.port, credentials=("sensor", "s3cret"))
        good = self.start(ftd_args(self.broker.port, "--mqtt-credentials", cred))
        self.host.wait_kind("DBIRTH")
        good.stop()
        self.assertNotIn("readable by others", good.text())
        os.chmod(wrong, 0o644)
        refused = self.start(ftd_args(self.broker.port, "--mqtt-credentials", wrong), "refused")
        time.sleep(1.5)
        refused.stop()
        self.assertIn("refused the connection", refused.text())
        self.assertIn("readable by others", refused.text())
        for bad, says in ((["--mqtt", "mqtt://u:p@127.0.0.1:1883"], "--mqtt-credentials"),
                          (["--mqtt", "http://127.0.0.1"], "mqtt://"),
                          (["--mqtt", "mqtt://127.0.0.1", "--edge-node", "a/b"], "--edge-node"),
                          (["--mqtt-rate-hz", "5"], "--mqtt")):
            r = subprocess.run([os.environ["FTD"], "--adc", "sim", *bad], capture_output=True,
                               text=True, timeout=20)
            self.assertNotEqual(r.returncode, 0, bad)
            self.assertIn(says, r.stderr, bad)


if __name__ == "__main__":
    unittest.main()
