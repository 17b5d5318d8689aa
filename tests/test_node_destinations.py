"""Addresses the node and the simulated robots send to are checked once, at start: port 0 or a host that does not
resolve is one error line naming the option (it was a traceback at the first send, or a failed send and a fresh
name lookup for every team state)."""

from __future__ import annotations

import pytest
from typer.testing import CliRunner

from lookalike.cli import app
from lookalike.node import Endpoint, NodeConfig, NodeServer
from lookalike.node.client import resolve_destination
from tests.test_node_identifier import HeadingMatcher

NOT_DESTINATIONS = [("127.0.0.1", 0), ("nosuchhost.invalid", 7700)]


@pytest.mark.parametrize("address", NOT_DESTINATIONS)
def test_no_destination_is_refused_naming_it(address):
    with pytest.raises(ValueError, match=f"address {address[0]}:{address[1]}"):
        resolve_destination(address)
    with pytest.raises(ValueError, match=address[0]):
        Endpoint(address)
    with pytest.raises(ValueError, match=address[0]):
        NodeServer(HeadingMatcher(), NodeConfig(publish=(address,)))


def test_host_names_are_looked_up_once():
    assert resolve_destination(("localhost", 7800)) == ("127.0.0.1", 7800)
    with Endpoint(("localhost", 7800)) as endpoint:
        assert endpoint.peer == ("127.0.0.1", 7800)


@pytest.mark.parametrize("command", [["serve", "--duration", "0.1", "--listen", "127.0.0.1:0", "--publish"],
                                     ["robot-sim", "--robot", "1", "--duration", "0.1", "--node"],
                                     ["camera-sim", "--duration", "0.1", "--node"]])
@pytest.mark.parametrize("address", ["127.0.0.1:0", "nosuchhost.invalid:7700"])
def test_cli_names_the_option(command, address):
    result = CliRunner().invoke(app, [*command, address])
    assert result.exit_code == 2, result.output
    assert f"{command[-1]}: address {address}" in result.output and "Traceback" not in result.output
