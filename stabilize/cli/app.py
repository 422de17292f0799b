"""The typer app that every command registers with, its version flag, and the one way
a command fails: one ``error:`` line on stderr and exit status 2."""

from __future__ import annotations

from importlib.metadata import PackageNotFoundError, version
from typing import NoReturn

import typer

app = typer.Typer(
    name="stabilize",
    help=(
        "Video stabilisation from a robust camera-rotation estimator "
        "(Hough transform on SO(3), ICCV 2023)."
    ),
    no_args_is_help=True,
    add_completion=False,
    rich_markup_mode="markdown",
)


def package_version() -> str:
    """The installed package's version ('unknown' in a source tree never installed)."""
    try:
        return version("hough-stabilize")
    except PackageNotFoundError:
        return "unknown"


def _print_version(value: bool) -> None:
    if value:
        typer.echo(f"stabilize {package_version()}")
        raise typer.Exit()


@app.callback()
def _root(
    version_flag: bool = typer.Option(
        False, "--version", callback=_print_version, is_eager=True, help="Print the version."
    ),
) -> None:
    """Video stabilisation from a robust camera-rotation estimator."""


def fail(message: str) -> NoReturn:
    """One clear line on stderr and a non-zero exit."""
    typer.echo(f"error: {message}", err=True)
    raise typer.Exit(2)
