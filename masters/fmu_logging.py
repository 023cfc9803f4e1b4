"""Logger callbacks for fmpy that keep an FMU's log messages for inspection.

fmpy's own default logger prints; tests and masters want the messages as data (an FMU's
error message is how it says what went wrong). The variadic FMI logger is turned into a
plain one by fmpy's logger proxy, which formats the message with vsnprintf.
"""

from ctypes import byref

from fmpy.fmi1 import calloc, free
from fmpy.fmi2 import (
    fmi2CallbackAllocateMemoryTYPE,
    fmi2CallbackFreeMemoryTYPE,
    fmi2CallbackFunctions,
    fmi2CallbackLoggerTYPE,
)
from fmpy.logging import addLoggerProxy

STATUS = ["OK", "WARNING", "DISCARD", "ERROR", "FATAL", "PENDING"]


# fmpy's logging proxy (`addLoggerProxy`, its logging.so) keeps one process-wide pointer to
# the last logger it was given, and fmpy's default callbacks go through that proxy too. A
# MessageLog freed while the pointer still names its logger closure leaves every later FMU
# that logs (fmpy.simulate_fmu, fmpy.ssp) calling freed memory: a SIGSEGV inside the FMU's
# fmi2DoStep as soon as it logs a line. Every logger handed to the proxy is kept alive here for
# the life of the process.
_PROXIED = []


class MessageLog:
    """Collects (status, category, message) tuples from one or more FMU instances."""

    def __init__(self, echo=False):
        self.messages = []
        self.echo = echo
        self._logger = fmi2CallbackLoggerTYPE(self._log)
        self.callbacks = fmi2CallbackFunctions()
        self.callbacks.logger = self._logger
        self.callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        self.callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        addLoggerProxy(byref(self.callbacks))
        _PROXIED.append(self)

    def _log(self, env, instance, status, category, message):
        entry = (STATUS[status], category.decode(), message.decode("utf-8", "replace"))
        self.messages.append(entry)
        if self.echo:
            print(f"[{entry[0]}] {instance.decode()}: {entry[2]}")

    def text(self, min_status="OK"):
        level = STATUS.index(min_status)
        return "\n".join(m for s, _, m in self.messages if STATUS.index(s) >= level)
