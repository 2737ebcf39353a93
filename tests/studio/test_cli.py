"""``wmrkit studio`` on the command line: a real server process answers, user mistakes exit 2 with one line."""

from __future__ import annotations

import json
import socket
import subprocess
import sys
import time
import urllib.request

import pytest

from wmrkit import catalog
from wmrkit.cli.main import main

pytest.importorskip("uvicorn")
pytest.importorskip("starlette")


def test_unknown_robot_exits_2(capsys):
    assert main(["studio", "no-such-robot", "--no-browser"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("wmrkit: error:") and "no robot 'no-such-robot'" in err and len(err.splitlines()) == 1


def test_bad_port_exits_2(capsys):
    assert main(["studio", "diff-drive", "--port", "70000", "--no-browser"]) == 2
    assert "--port" in capsys.readouterr().err


def test_port_in_use_and_bad_host_are_one_line(capsys):
    """uvicorn logged 'ERROR: [Errno 98] ...' and exited with code 3 (and warned about a bad host as reachable)."""
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        assert main(["studio", "diff-drive", "--port", str(port), "--no-browser"]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and f"127.0.0.1:{port}" in err and "--port 0" in err, err
    assert main(["studio", "diff-drive", "--host", "no such host!", "--port", "0", "--no-browser"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--host" in err and "no such host!" in err, err


def test_server_process_serves_the_file(tmp_path):
    catalog.load("omni-3").to_file(tmp_path / "mine.yaml")
    proc = subprocess.Popen([sys.executable, "-m", "wmrkit", "studio", str(tmp_path / "mine.yaml"), "--port", "0",
                             "--no-browser"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        line = proc.stdout.readline()  # "wmrkit studio: http://127.0.0.1:PORT/ (folder ...)"
        assert line.startswith("wmrkit studio: http://127.0.0.1:"), (line, proc.stderr.read() if proc.poll() else "")
        url = line.split()[2]
        deadline = time.monotonic() + 20
        while True:
            try:
                meta = json.load(urllib.request.urlopen(url + "api/meta", timeout=5))
                break
            except OSError:
                if time.monotonic() > deadline:
                    raise
                time.sleep(0.1)
        assert meta["start"]["spec"] == "mine.yaml" and meta["files"] == ["mine.yaml"]
        assert meta["start"]["description"] == catalog.load("omni-3").to_dict()
        assert urllib.request.urlopen(url, timeout=5).read().startswith(b"<!doctype html>")
    finally:
        proc.terminate()
        proc.wait(10)


def test_a_linked_file_is_opened_and_saved_where_it_is(tmp_path, monkeypatch):
    """`wmrkit studio robots/current.yaml`, a link to designs/v3.yaml: the studio served designs/ but offered to
    save as 'current.yaml' there, a new file beside the one the user opened."""
    from wmrkit.studio import app as studio_app

    (tmp_path / "designs").mkdir()
    (tmp_path / "robots").mkdir()
    catalog.load("omni-3").to_file(tmp_path / "designs" / "v3.yaml")
    (tmp_path / "robots" / "current.yaml").symlink_to(tmp_path / "designs" / "v3.yaml")
    seen = {}

    def create_app(root, robot, *, robot_spec=None, allowed_hosts=None):
        seen.update(root=root, spec=robot_spec)
        raise KeyboardInterrupt  # stop before serving

    monkeypatch.setattr(studio_app, "create_app", create_app)
    with pytest.raises(KeyboardInterrupt):
        main(["studio", str(tmp_path / "robots" / "current.yaml"), "--port", "0", "--no-browser"])
    assert seen == {"root": (tmp_path / "designs").resolve(), "spec": "v3.yaml"}


def test_the_start_file_warnings_are_wmrkit_warning_lines(tmp_path, monkeypatch, capsys):
    """A start file with a mecanum wheel at gamma 90 deg: Python's two-line DescriptionWarning (the source line of
    description.py) was printed; now the one ``wmrkit: warning:`` line `wmrkit show` prints for the same file."""
    from wmrkit.studio import app as studio_app

    path = tmp_path / "mg.yaml"
    path.write_text(catalog.source_text("mecanum-4").replace("type: mecanum,", "type: mecanum, gamma: 90 deg,", 1))
    assert main(["show", str(path)]) == 0
    want = capsys.readouterr().err
    assert want.startswith(f"wmrkit: warning: {path}:") and want.count("\n") == 1, want

    def create_app(root, robot, *, robot_spec=None, allowed_hosts=None):
        raise KeyboardInterrupt  # stop before serving

    monkeypatch.setattr(studio_app, "create_app", create_app)
    with pytest.raises(KeyboardInterrupt):
        main(["studio", str(path), "--port", "0", "--no-browser"])
    assert capsys.readouterr().err == want


def test_a_loopback_host_answers_at_its_own_address(tmp_path, monkeypatch):
    """`--host 127.0.0.2` (a loopback address) printed and opened http://127.0.0.2:PORT/, which answered 400
    'Invalid host header': only the Host names 127.0.0.1, localhost and ::1 were answered."""
    pytest.importorskip("httpx2")
    from starlette.testclient import TestClient

    from wmrkit.studio import app as studio_app

    real_create_app, seen = studio_app.create_app, {}

    def create_app(root, robot, *, robot_spec=None, allowed_hosts=None):
        seen["hosts"] = allowed_hosts
        raise KeyboardInterrupt  # stop before serving

    monkeypatch.setattr(studio_app, "create_app", create_app)
    with pytest.raises(KeyboardInterrupt):
        main(["studio", "diff-drive", "--host", "127.0.0.2", "--port", "0", "--no-browser"])
    app = real_create_app(tmp_path, allowed_hosts=seen["hosts"])
    assert TestClient(app, base_url="http://127.0.0.2:8765").get("/api/meta").status_code == 200
    assert TestClient(app, base_url="http://localhost:8765").get("/api/meta").status_code == 200
    assert TestClient(app, base_url="http://evil.example").get("/api/meta").status_code == 400



@pytest.mark.parametrize("host", ["127.1", "127.0.0.1"])
def test_loopback_is_known_by_the_address_listened_on(tmp_path, monkeypatch, capsys, host):
    """`--host 127.1` listens on 127.0.0.1, but was taken for another machine's address: a false warning that other
    machines could reach the studio, and every Host header answered (no protection against DNS rebinding)."""
    pytest.importorskip("httpx2")
    import uvicorn
    from starlette.testclient import TestClient

    from wmrkit.studio import app as studio_app

    real_create_app, seen = studio_app.create_app, {}

    def create_app(root, robot, *, robot_spec=None, allowed_hosts=None):
        seen["app"] = real_create_app(tmp_path, robot, allowed_hosts=allowed_hosts)
        return seen["app"]

    class Server:  # serves nothing: closes the socket the command bound
        def __init__(self, config):
            self.started, self.should_exit, self.servers = True, True, []

        def run(self, sockets):
            for sock in sockets:
                sock.close()

    monkeypatch.setattr(studio_app, "create_app", create_app)
    monkeypatch.setattr(uvicorn, "Server", Server)
    assert main(["studio", "diff-drive", "--host", host, "--port", "0", "--no-browser"]) == 0
    assert "warning" not in capsys.readouterr().err
    assert TestClient(seen["app"], base_url="http://127.0.0.1:8765").get("/api/meta").status_code == 200
    assert TestClient(seen["app"], base_url="http://evil.example").get("/api/meta").status_code == 400
