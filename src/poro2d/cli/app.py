"""The ``poro2d`` app: every command registered, and :func:`main`, the console entry point.

The commands are the modules beside this one (``poro2d.cli.convert``, ...); each drives
the Python function of its layer. Bad input anywhere below raises
:class:`poro2d.errors.InputError`, which :func:`main` prints as one line with
exit code 2 and no traceback.
"""

from __future__ import annotations

import functools
import importlib
import inspect
import sys

import typer
import typer.core
from rich.console import Console

from poro2d import __version__
from poro2d.console import shown
from poro2d.errors import InputError, Interrupted
from poro2d.worker_signals import forget_unhandled_interrupt, ignore_interrupts_in_dask_worker

# a worker process of the local cluster imports this module first (as its main module)
ignore_interrupts_in_dask_worker()

app = typer.Typer(
    name="poro2d",
    help="2D porosities for DEM studies: conversions, DEM engine, the paper's criterion.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)
err_console = Console(stderr=True)


def _version_callback(value: bool) -> None:
    if value:
        typer.echo(f"poro2d {__version__}")
        raise typer.Exit()


@app.callback()
def _root(
    version: bool = typer.Option(
        False, "--version", callback=_version_callback, is_eager=True, help="Print the version."
    ),
) -> None:
    """poro2d command line."""


#: the command modules beside this one, in the order ``poro2d --help`` lists their commands
COMMANDS = (
    "convert plot criterion shear biaxial critical_state strength paper sweep relation export import_specimen"
    " sensitivity calibrate sand"
).split()


def _register() -> None:
    # Imported here so that `poro2d --help` stays cheap and a broken optional
    # layer cannot take the whole CLI down at import time.
    for name in COMMANDS:
        importlib.import_module(f"poro2d.cli.{name}").register(app)
    for info in app.registered_commands:
        info.callback = _interruptible(info.name or info.callback.__name__, info.callback)
    for info in _all_commands(app):
        info.short_help = info.short_help or summary_line(info.help or inspect.getdoc(info.callback))


def _all_commands(typer_app: typer.Typer) -> list:
    """The command infos of ``typer_app`` and of the groups added to it (``plot``)."""
    infos = list(typer_app.registered_commands)
    for group in typer_app.registered_groups:
        infos += _all_commands(group.typer_instance)
    return infos


def summary_line(doc: str | None) -> str | None:
    """The first paragraph of a command's docstring as one line: the line ``poro2d --help`` lists.

    The rich help keeps a paragraph's line breaks as they are in the source, so a summary
    wrapped there would break mid-sentence in the list of commands.
    """
    if not doc:
        return None
    return " ".join(doc.strip().split("\n\n")[0].split())


def show_flags_as_flags() -> None:
    """Leave a flag's type out of the rich help, as the plain help does (``--quiet``, not
    ``--quiet <bool>``, which reads as if the flag took a value).

    typer's rich help prints a type beside every option, flags included; the rule is set here,
    once, on its option class, so that every command and ``--help`` itself follow it.
    """
    option = getattr(typer.core, "TyperOption", None)
    typed = getattr(option, "display_type_rich", None)
    if typed is None or getattr(typed, "leaves_flags_bare", False):
        return  # a typer without the method, or this module imported again

    def display_type_rich(self, ctx):
        return None if self.is_flag and not self.count else typed(self, ctx)

    display_type_rich.leaves_flags_bare = True
    option.display_type_rich = display_type_rich


#: what an interrupted command leaves in its --out folder, for the message
KEPT = {
    "criterion": "finished trials",
    "shear": "finished tests and the last checkpoint of each running one",
    "paper": "finished stages, trials and tests",
    "sweep": "finished cases",
    "relation": "finished cases",
    "sensitivity": "finished cases",
    "strength": "finished specimens and tests",
    "sand": "finished calibration cases and specimens",
}


def interrupt_message(command: str, out) -> str:
    """One line: what an interrupted ``command`` kept and how to go on."""
    kept = KEPT.get(command)
    if kept is None or out is None:
        return "interrupted"
    return f"interrupted: {kept} are kept in {out}; rerun the same command to resume"


def _interruptible(command: str, callback):
    """``callback`` with Ctrl-C turned into :class:`Interrupted`, which reaches :func:`main`.

    The command line library catches ``KeyboardInterrupt`` itself and exits with
    code 130 without a word; an ordinary exception passes through it.
    """

    @functools.wraps(callback)
    def run(*args, **kwargs):
        try:
            return callback(*args, **kwargs)
        except KeyboardInterrupt:
            raise Interrupted(interrupt_message(command, kwargs.get("out"))) from None

    return run


show_flags_as_flags()
_register()


def main(argv: list[str] | None = None) -> None:
    """Console entry point: run the app, turn InputError into a one-line message."""
    try:
        args = sys.argv[1:] if argv is None else argv
        check_raw_arguments(args)
        rc = app(args=argv, standalone_mode=False)
        if rc == 130:  # a Ctrl-C while the options are parsed, outside the command: typer's silent Exit(130)
            raise KeyboardInterrupt
        if isinstance(rc, int) and rc != 0:  # typer.Exit(code) comes back as a return value here
            sys.exit(rc)
    except InputError as exc:
        # shown as text: a message naming a config table ("[specimen] max_disks") is not markup,
        # and a name from the user's file may hold control characters
        err_console.print(f"[bold red]error:[/] {shown(str(exc))}", highlight=False, soft_wrap=True)
        sys.exit(2)
    except Interrupted as exc:
        err_console.print(f"[yellow]{exc}[/]", highlight=False, soft_wrap=True)
        forget_unhandled_interrupt()
        sys.exit(130)
    except KeyboardInterrupt:  # outside a command (while parsing the options, say)
        err_console.print("[yellow]interrupted[/]")
        forget_unhandled_interrupt()
        sys.exit(130)
    except SystemExit:
        raise
    except Exception as exc:  # usage errors of click (or the copy of it that typer ships)
        if _is_click(exc, "ClickException"):
            # one line as for every other refusal: no usage banner, no "Try --help" line
            line = usage_line(exc, sys.argv[1:] if argv is None else argv)
            err_console.print(f"[bold red]error:[/] {shown(line)}", highlight=False, soft_wrap=True)
            sys.exit(exc.exit_code)  # type: ignore[attr-defined]
        if _is_click(exc, "Abort"):
            err_console.print("[yellow]aborted[/]")
            sys.exit(1)
        raise


def check_raw_arguments(argv: list[str]) -> None:
    """What the option parser would let pass without a word, refused on one line.

    An empty value (``--out ""``, ``--n-lab=``): no option of poro2d has a meaning for
    it, and a path option takes it for the current folder (``Path("")`` is ``.``). An
    option given twice (``--n-lab 0.3 ... --n-lab 0.4``, ``-o a --out b``): the parser
    keeps the last; which one was meant is the user's to say.
    """
    params = _command_params(argv)
    seen: dict[object, list[str]] = {}
    for k, arg in enumerate(argv):
        if arg == "--":
            break
        name, eq, value = arg.partition("=")
        param = next((p for p in params if name in p.opts), None)
        if param is None:  # not an option of the command (its value, an argument, a typo)
            continue
        is_flag = bool(getattr(param, "is_flag", False))
        has_next = k + 1 < len(argv)
        if not is_flag and ((eq and not value) or (not eq and has_next and argv[k + 1] == "")):
            raise InputError(name, "", "a non-empty value")
        bare = eq or is_flag or not has_next
        seen.setdefault(param, []).append(arg if bare else f"{arg} {argv[k + 1]}")
    for param, given in seen.items():
        if len(given) > 1 and not getattr(param, "multiple", False):  # a repeatable option keeps each
            raise InputError(max(param.opts, key=len), ", ".join(given), "the option once")


def _command_params(argv: list[str]) -> list:
    """The parameters of the (sub)command that ``argv`` names (each with its spellings, ``opts``)."""
    import typer.main

    command = typer.main.get_command(app)
    for arg in argv:
        commands = getattr(command, "commands", None)
        if not commands or arg not in commands:
            break
        command = commands[arg]
    return list(getattr(command, "params", []))


def usage_line(exc, argv: list[str]) -> str:
    """A usage error of the command line library as one line.

    A value that does not convert (``--seed 1e3``) reads like every other refusal: the
    option, the value given and what is allowed; an unknown option lists the command's own.
    """
    param = getattr(exc, "param", None)
    if _is_click(exc, "BadParameter") and not _is_click(exc, "MissingParameter") and param is not None:
        name = max(param.opts, key=len) if param.opts else param.name
        allowed = str(exc.message).removeprefix("Input should be ").split(", unable to")[0]
        return f"{name} = {_given(argv, param.opts)!r} is invalid; allowed: {allowed}"
    line = " ".join(str(exc.format_message()).split())
    ctx = getattr(exc, "ctx", None)
    if _is_click(exc, "NoSuchOption") and ctx is not None:
        known = sorted(o for p in ctx.command.params for o in p.opts if o.startswith("--"))
        line = f"no such option: {exc.option_name}; the options of {ctx.info_name}: {', '.join(known)}"
    return line


def _given(argv: list[str], opts: list[str]) -> str | None:
    """What followed the last of ``opts`` in ``argv`` (``--opt value`` or ``--opt=value``)."""
    given = None
    for k, arg in enumerate(argv):
        for opt in opts:
            if arg == opt and k + 1 < len(argv):
                given = argv[k + 1]
            elif arg.startswith(opt + "=") and opt.startswith("--"):
                given = arg[len(opt) + 1 :]
    return given


def _is_click(exc: BaseException, name: str) -> bool:
    """True if ``exc`` is click's ``name`` exception, from click itself or typer's bundled copy."""
    mods = []
    try:
        import click

        mods.append(click.exceptions)
    except ImportError:  # pragma: no cover
        pass
    try:
        from typer._click import exceptions as tce  # typer >= 0.29 bundles click

        mods.append(tce)
    except ImportError:
        pass
    return any(isinstance(exc, getattr(m, name)) for m in mods if hasattr(m, name))


if __name__ == "__main__":  # pragma: no cover
    main()
