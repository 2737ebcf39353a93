"""``wmrkit studio``: design a robot in the browser with live kinematics (a local web server; docs/studio.md)."""

from __future__ import annotations

import argparse
import errno
import ipaddress
import socket
import threading
import webbrowser
from pathlib import Path

from ..errors import WmrkitError
from ._common import load_robot, warn


def add_parsers(commands: argparse._SubParsersAction) -> None:
    """Register ``studio``."""
    p = commands.add_parser("studio", help="design a robot in the browser and see its kinematics live")
    p.add_argument("robot", metavar="ROBOT", nargs="?", default="diff-drive",
                   help="catalog name or a .yaml/.json file to start with (default: diff-drive); files are opened "
                        "and saved only inside the file's folder (or the current folder)")
    p.add_argument("--port", type=int, default=8765, help="TCP port (default 8765; 0 picks a free one)")
    p.add_argument("--host", default="127.0.0.1",
                   help="interface to listen on (default 127.0.0.1: this machine only)")
    p.add_argument("--no-browser", action="store_true", help="do not open a web browser")
    p.set_defaults(run=run_studio)


def run_studio(args: argparse.Namespace) -> int:
    """Start the server (blocking until Ctrl+C) and open the page."""
    from ..studio.app import LOCAL_HOSTS, create_app

    spec = args.robot
    path = Path(spec)
    if path.suffix.lower() in (".yaml", ".yml", ".json") or path.exists():
        target = path.resolve()  # a symbolic link: the file it names, in the folder served (opened and saved there)
        root, spec = target.parent, target.name
    else:
        root = Path.cwd()
    robot = load_robot(args.robot)  # its description's warnings said as warning lines (the page shows them too)
    if not 0 <= args.port <= 65535:
        raise WmrkitError(f"--port: from 0 to 65535, got {args.port}")
    shown = f"[{args.host}]" if ":" in args.host else args.host
    try:
        sock = _listen(args.host, args.port)
    except OSError as err:  # uvicorn logged its own 'ERROR:' line and exited with code 3
        hint = " (try --port 0 for a free one)" if err.errno == errno.EADDRINUSE else ""
        raise WmrkitError(f"--host/--port: cannot listen on {shown}:{args.port}: {err.strerror or err}{hint}") from None
    # on a loopback interface, only this machine's names and the address listened on (127.0.0.2 is one too);
    # loopback or not by the address bound, not by how --host spells it (127.1 was taken for another machine's)
    bound = sock.getsockname()[0]
    loopback = _loopback(bound)
    local = [*LOCAL_HOSTS, args.host, bound] if loopback else None
    app = create_app(root, robot, robot_spec=spec, allowed_hosts=local)
    from ..studio import api

    api.analyze_live({"description": robot.to_dict()})  # warm the imports and compiled kernels before serving
    import uvicorn

    config = uvicorn.Config(app, host=args.host, port=args.port, log_level="warning")
    server = uvicorn.Server(config)
    if not loopback:
        warn(f"listening on {args.host}: other machines can reach the studio and its folder")

    def announce() -> None:
        while not server.started:
            if server.should_exit:
                return
            threading.Event().wait(0.05)
        port = server.servers[0].sockets[0].getsockname()[1] if server.servers else args.port
        url = f"http://{'127.0.0.1' if args.host in ('0.0.0.0', '::') else shown}:{port}/"
        print(f"wmrkit studio: {url} (folder {root}; Ctrl+C stops)", flush=True)
        if not args.no_browser:
            webbrowser.open(url)

    threading.Thread(target=announce, daemon=True).start()
    try:
        server.run(sockets=[sock])
    except KeyboardInterrupt:
        pass
    if not server.started:
        raise WmrkitError(f"the server on {shown}:{args.port} did not start")
    return 0


def _listen(host: str, port: int) -> socket.socket:
    """A socket listening on `host`:`port`, bound here so that a port in use or an unknown host is one line.
    A name with IPv4 and IPv6 addresses (``localhost``) listens on its first IPv4 one."""
    found = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM, flags=socket.AI_PASSIVE)
    family, _, _, _, address = min(found, key=lambda a: a[0] != socket.AF_INET)
    sock = socket.socket(family, socket.SOCK_STREAM)
    try:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)  # as uvicorn: restart at once on the same port
        sock.bind(address)
        sock.listen()
    except OSError:
        sock.close()
        raise
    return sock


def _loopback(host: str) -> bool:
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False
