"""Command-line usage errors as one line, like every other bad input.

click reports a bad argument with a usage block of several lines; `OneLineGroup` prints
`error: VALUE: ARGUMENT: CAUSE; FIX` instead (exit status 2), and `UserPath` is click's Path
that remembers the value it refused and refuses a NUL byte instead of crashing on it.
"""

import sys

import click


def one_line(text) -> str:
    """`text` on one line: line breaks and other control characters are shown escaped."""
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in str(text))


class UserPath(click.Path):
    """click.Path whose refusal carries the refused value (`BadParameter.value`)."""

    def convert(self, value, param, ctx):
        if isinstance(value, str) and "\0" in value:
            error = click.BadParameter("the path holds a NUL byte", ctx=ctx, param=param)
            error.value = value  # type: ignore[attr-defined]  # the refused value, read by the usage line
            raise error
        try:
            return super().convert(value, param, ctx)
        except click.BadParameter as error:
            error.value = value  # type: ignore[attr-defined]
            raise


def usage_line(error: click.UsageError) -> str:
    """`VALUE: ARGUMENT: CAUSE; FIX` of a click usage error (VALUE is 'command line' if unknown)."""
    ctx = error.ctx
    command = ctx.command_path if ctx is not None else "aotv-cosim"
    param = getattr(error, "param", None)
    value = getattr(error, "value", None)
    parts = [one_line(value) if value is not None else "command line"]
    if param is not None:
        parts.append(one_line(param.get_error_hint(ctx) if ctx is not None else param.name).replace('"', "'"))
    cause = " ".join(one_line(error.format_message()).split())
    return f"{': '.join([*parts, cause])}; see '{command} --help'"


class OneLineGroup(click.Group):
    """A click group whose usage errors are one line on stderr, exit status 2."""

    def main(self, args=None, prog_name=None, complete_var=None, standalone_mode=True, **extra):
        if not standalone_mode:
            return super().main(args, prog_name, complete_var, standalone_mode, **extra)
        try:
            result = super().main(args, prog_name, complete_var, False, **extra)
        except click.UsageError as error:
            click.echo(f"error: {usage_line(error)}", err=True)
            sys.exit(2)
        except click.ClickException as error:
            click.echo(f"error: {one_line(error.format_message())}", err=True)
            sys.exit(error.exit_code)
        except click.Abort:
            click.echo("error: aborted", err=True)
            sys.exit(1)
        sys.exit(result if isinstance(result, int) else 0)
