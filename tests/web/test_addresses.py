"""The address helpers made public by the split of :mod:`sandbox.web.serving.network`."""

from __future__ import annotations

import pytest

from sandbox.web.serving.addresses import netloc


def test_netloc_gives_a_urls_host_as_compared_and_its_port():
    assert netloc("http://Sandbox.Lycee.fr/") == ("sandbox.lycee.fr", 80)
    assert netloc("https://sandbox.lycee.fr") == ("sandbox.lycee.fr", 443)
    assert netloc("http://[::ffff:10.0.0.5]:8080") == ("10.0.0.5", 8080)
    for bad in ("javascript:alert(1)", "ftp://host/", "/relative"):
        with pytest.raises(ValueError):
            netloc(bad)
