"""The exceptions of vrflow.app: each carries what a person needs to fix the problem."""


class VrflowError(Exception):
    """Base of every error vrflow.app raises."""


class LoadError(VrflowError):
    """A file could not be read or loaded; the message names the file (and line)."""


class ValidationError(VrflowError):
    """The application is invalid: `diagnostics` are the problems, `text` what
    `vrflow validate` prints for them."""

    def __init__(self, validation):
        self.validation = validation
        self.diagnostics = list(validation.diagnostics)
        self.text = validation.text
        super().__init__(self.text.rstrip("\n"))


class RunError(VrflowError):
    """`vrflow run` or `vrflow launch` failed. `exit_code` and `status` are the program's
    (docs/report.md), `report` the run report when one was written (None otherwise),
    `diagnostics` the lines of problems it printed for an invalid application (exit 2),
    `stderr` all it printed."""

    def __init__(self, command, exit_code, report, stderr):
        self.command = command
        self.exit_code = exit_code
        self.report = report
        self.stderr = stderr
        self.status = report.get("status") if report else ("invalid" if exit_code == 2 else None)
        # An invalid application (exit 2, nothing ran): the program printed only its problems,
        # as `vrflow validate` does.
        self.diagnostics = stderr.splitlines() if exit_code == 2 else []
        error = report.get("error") if report else ""
        summary = error or "\n".join(self.diagnostics) or stderr.strip()
        super().__init__(f"vrflow {command} exited with status {exit_code}"
                         + (f" ({self.status})" if self.status else "")
                         + (f": {summary}" if summary else ""))
