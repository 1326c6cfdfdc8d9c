# SPDX-License-Identifier: Apache-2.0
"""
The dashboard's web server: the page bundled at setup time, and its configuration.

Serves ``share/wirefish_view/dashboard/`` (index.html and the esbuild bundle `make setup`
builds from web/), ``/config.json`` (the WebSocket port, namespace, drive limits, frames) and
``/favicon.ico`` (a fish, as SVG: browsers ask for it whatever the page says).
Nothing is fetched from elsewhere: the page works offline.
"""

from __future__ import annotations

from functools import partial
from http.server import SimpleHTTPRequestHandler, ThreadingHTTPServer
import json
from pathlib import Path
import threading

FAVICON = (b'<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 32 32">'
           b'<ellipse cx="13" cy="16" rx="11" ry="7" fill="#1565c0"/>'
           b'<path d="M22 16 L31 8 L31 24 Z" fill="#ef6c00"/>'
           b'<circle cx="7" cy="14" r="1.6" fill="#fff"/></svg>')
MISSING = (b'<!doctype html><title>wirefish view</title><p>The dashboard is not built: run '
           b'<code>make setup</code> (npm ci and the bundle of src/wirefish_view/web).')


def dashboard_dir() -> Path:
    """Return the installed dashboard directory (it may not exist: no bundle built)."""
    from ament_index_python.packages import get_package_share_directory
    return Path(get_package_share_directory('wirefish_view'), 'dashboard')


class _Handler(SimpleHTTPRequestHandler):
    config = b'{}'

    def do_GET(self) -> None:  # noqa: N802 (http.server's name)
        """Answer /config.json, a missing page's hint, or a file of the bundle."""
        if self.path == '/config.json':
            self._send(200, 'application/json', self.config)
        elif self.path == '/favicon.ico':
            self._send(200, 'image/svg+xml', FAVICON)
        elif self.path in ('/', '/index.html') and not Path(self.directory,
                                                            'index.html').exists():
            self._send(503, 'text/html', MISSING)
        else:
            super().do_GET()

    def _send(self, code: int, kind: str, body: bytes) -> None:
        self.send_response(code)
        self.send_header('Content-Type', kind)
        self.send_header('Content-Length', str(len(body)))
        self.send_header('Cache-Control', 'no-store')
        self.end_headers()
        self.wfile.write(body)

    def log_message(self, format: str, *args) -> None:  # noqa: A002 (http.server's name)
        """Keep the node's log for the node (no line per request)."""


class DashboardServer:
    """A threaded HTTP server of the dashboard on ``address``:``port`` (0: a free port)."""

    def __init__(self, address: str, port: int, config: dict,
                 directory: Path | None = None) -> None:
        """Bind and serve in a daemon thread."""
        handler = type('DashboardHandler', (_Handler,), {'config': json.dumps(config).encode()})
        self._httpd = ThreadingHTTPServer(
            (address, port), partial(handler, directory=str(directory or dashboard_dir())))
        self._httpd.daemon_threads = True
        self.port = self._httpd.server_address[1]
        self._thread = threading.Thread(target=self._httpd.serve_forever, name='dashboard',
                                        daemon=True)
        self._thread.start()

    def stop(self) -> None:
        """Stop serving and close the socket."""
        self._httpd.shutdown()
        self._httpd.server_close()
        self._thread.join(2.0)
