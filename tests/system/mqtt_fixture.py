"""Test fixtures for ftd over MQTT: a real mosquitto on a free loopback port with a generated
configuration (plain, TLS with a CA made by openssl here, or with a password file), ftd processes,
each in the test's own temporary directory and stopped by PID."""
import getpass
import os
import signal
import socket
import subprocess
import tempfile
import time


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def wait_port(port, timeout_s=10):
    deadline = time.time() + timeout_s
    while time.time() < deadline:
        try:
            with socket.create_connection(("127.0.0.1", port), timeout=0.2):
                return True
        except OSError:
            time.sleep(0.05)
    return False


def make_tls_files(d):
    """A self-signed CA and a server certificate for 127.0.0.1 / localhost signed by it."""
    def run(*args):
        subprocess.run(args, cwd=d, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    run("openssl", "req", "-x509", "-newkey", "rsa:2048", "-nodes", "-days", "2",
        "-keyout", "ca.key", "-out", "ca.crt", "-subj", "/CN=ftstack test CA")
    run("openssl", "req", "-newkey", "rsa:2048", "-nodes", "-keyout", "server.key",
        "-out", "server.csr", "-subj", "/CN=localhost")
    with open(os.path.join(d, "san.ext"), "w") as f:
        f.write("subjectAltName=IP:127.0.0.1,DNS:localhost\n")
    run("openssl", "x509", "-req", "-in", "server.csr", "-CA", "ca.crt", "-CAkey", "ca.key",
        "-CAcreateserial", "-out", "server.crt", "-days", "2", "-extfile", "san.ext")
    return {k: os.path.join(d, k + ".crt") for k in ("ca", "server")} | {
        "server_key": os.path.join(d, "server.key")}


class Broker:
    """mosquitto on 127.0.0.1:port (chosen here unless given) with a generated configuration."""

    def __init__(self, workdir, port=None, tls=None, password_file=None):
        self.workdir = workdir
        self.port = port or free_port()
        self.tls = tls
        self.password_file = password_file
        self.proc = None
        self.start()

    def start(self):
        conf = os.path.join(self.workdir, "mosquitto.conf")
        # Started as root, mosquitto would switch to the user 'mosquitto', who cannot read this
        # test's private files: it stays the user running the test.
        lines = [f"listener {self.port} 127.0.0.1", "persistence false",
                 f"user {getpass.getuser()}",
                 f"log_dest file {os.path.join(self.workdir, 'mosquitto.log')}",
                 "log_type error", "log_type warning", "log_type notice"]
        if self.password_file:
            lines += ["allow_anonymous false", f"password_file {self.password_file}"]
        else:
            lines += ["allow_anonymous true"]
        if self.tls:
            lines += [f"cafile {self.tls['ca']}", f"certfile {self.tls['server']}",
                      f"keyfile {self.tls['server_key']}"]
        with open(conf, "w") as f:
            f.write("\n".join(lines) + "\n")
        self.proc = subprocess.Popen(["mosquitto", "-c", conf], stdout=subprocess.DEVNULL,
                                     stderr=subprocess.DEVNULL)
        if not wait_port(self.port):
            self.stop()
            raise RuntimeError(f"mosquitto did not listen on {self.port}")

    def stop(self):
        if self.proc and self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
            try:
                self.proc.wait(5)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        self.proc = None


class Ftd:
    """One ftd process (simulated sensor) publishing to a broker."""

    def __init__(self, workdir, args, name="ftd"):
        self.stderr_path = os.path.join(workdir, name + ".stderr")
        self.stderr = open(self.stderr_path, "w")
        self.proc = subprocess.Popen([os.environ["FTD"]] + args, stdout=subprocess.DEVNULL,
                                     stderr=self.stderr)

    def text(self):
        with open(self.stderr_path) as f:
            return f.read()

    def stop(self, sig=signal.SIGTERM):
        if self.proc.poll() is None:
            self.proc.send_signal(sig)
            try:
                self.proc.wait(10)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        self.stderr.close()
        return self.proc.returncode


class TempDir:
    def __init__(self):
        self.tmp = tempfile.TemporaryDirectory(prefix="ftstack-mqtt-")
        self.path = self.tmp.name

    def cleanup(self):
        self.tmp.cleanup()
