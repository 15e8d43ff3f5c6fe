"""meshcat's server, bound to the loopback interface only.

meshcat's own ``meshcat-server`` binds its ZeroMQ socket to 127.0.0.1 but its web server to
every interface. This module runs the same bridge with the web server on 127.0.0.1 too, and
speaks the same protocol on stdout (``zmq_url=...`` and ``web_url=...`` lines), so
``meshcat.Visualizer(zmq_url=...)`` connects to it unchanged.

Run it as ``python -m planning.viz.viewer_server``; :func:`start_server` does that for you. It
exits when it is terminated or when the process that started it is gone.
"""

from __future__ import annotations

import contextlib
import os
import subprocess
import sys
from dataclasses import dataclass
from typing import Any

LOOPBACK = "127.0.0.1"


@dataclass
class ServerProcess:
    """A running loopback meshcat server.

    Attributes:
        process: the server's subprocess.
        zmq_url: where ``meshcat.Visualizer`` sends commands.
        web_url: the page a browser opens.
    """

    process: subprocess.Popen[str]
    zmq_url: str
    web_url: str

    def close(self) -> None:
        """Stop the server and wait for it to exit."""
        if self.process.poll() is None:
            self.process.terminate()
            try:
                self.process.wait(timeout=10)
            except subprocess.TimeoutExpired:  # pragma: no cover - tornado stops on SIGTERM
                self.process.kill()
                self.process.wait()
        if self.process.stdout is not None:
            self.process.stdout.close()


def start_server(timeout_s: float = 30.0) -> ServerProcess:
    """Start the loopback meshcat server in a subprocess and return its URLs."""
    process = subprocess.Popen(
        [sys.executable, "-u", "-m", "planning.viz.viewer_server"],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
        env=dict(os.environ),
    )
    urls: dict[str, str] = {}
    assert process.stdout is not None  # we asked for a pipe
    while len(urls) < 2:
        line = process.stdout.readline()
        if not line:
            process.wait(timeout=timeout_s)
            raise RuntimeError(
                f"the meshcat server exited with code {process.returncode} before it was ready"
            )
        key, _, value = line.strip().partition("=")
        if key in ("zmq_url", "web_url"):
            urls[key] = value
    return ServerProcess(process=process, zmq_url=urls["zmq_url"], web_url=urls["web_url"])


def _serve() -> None:
    import tornado.ioloop
    import tornado.web
    from meshcat.servers.zmqserver import ZMQWebSocketBridge

    class LoopbackApplication(tornado.web.Application):
        def listen(self, port: int, address: str | None = None, **kwargs: Any) -> Any:
            return super().listen(port, address=LOOPBACK, **kwargs)

    class LoopbackBridge(ZMQWebSocketBridge):  # type: ignore[misc]
        def make_app(self) -> tornado.web.Application:
            app: tornado.web.Application = super().make_app()
            app.__class__ = LoopbackApplication
            return app

    bridge = LoopbackBridge(host=LOOPBACK)
    parent = os.getppid()

    def orphaned() -> None:  # the process that started us is gone: nobody will close us
        if os.getppid() != parent:
            bridge.ioloop.stop()

    tornado.ioloop.PeriodicCallback(orphaned, 500).start()
    print(f"zmq_url={bridge.zmq_url}", flush=True)
    print(f"web_url={bridge.web_url}", flush=True)
    with contextlib.suppress(KeyboardInterrupt):
        bridge.run()


if __name__ == "__main__":
    _serve()
