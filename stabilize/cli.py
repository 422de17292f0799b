"""The ``stabilize`` command line: one typer app.

``stabilize IN OUT [options]`` is the main job; ``rotations``, ``synth``,
``evaluate``, ``compare`` and ``batch`` are subcommands, each added by the module
that implements it. This module is only the shell: version, help and dispatch.
"""

from __future__ import annotations

from importlib.metadata import PackageNotFoundError, version

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
    try:
        return version("hough-stabilize")
    except PackageNotFoundError:  # running from a source tree that was not installed
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


def main() -> None:
    """Console-script entry point."""
    app()


if __name__ == "__main__":
    main()
