"""The operator mixin of every job (DESIGN.md "Layers"): one shape for Bake, Bake Flames, Build
Surfaces, Build Toon Smoke, Build Flow Graph, Synthesize Fire and Export Mesh.

    class PLUME_OT_x(JobOperator, bpy.types.Operator):
        def make_runner(self, context):
            return XJob()

Both paths run the job's work in a child process (process.py): execute() waits for it
(``blender -b``, scripts, tests: bad input raises RuntimeError; a crashed child too), invoke()
(a button) runs prepare() at once and starts the child while a modal timer shows "<label> i of
N, ~s left (Esc cancels)" in the status bar and the progress cursor; Esc cancels at the child's
next unit of work (killing it after a grace period); deleting an object the job works on
cancels it; the result is built on the main thread when the child is done. No Python thread of
Plume runs in Blender's process. A job whose runner forecasts more than
LONG_JOB_S asks first (a dialog saying how long, OK starts it); headless, the forecast is printed
when the job starts and repeated in its report. Blender calls cancel() when it removes the
modal handler (quit, window closed, file load): the job is aborted and nothing is built."""

import time
import traceback

import bpy

from ..settings import BakeError
from . import registry
from .process import JobProcess

#: Seconds between two polls of the modal timer (progress, cancel, deleted objects).
POLL_S = 0.1
#: Seconds of main-thread steps per poll, and between two such polls: the interface stays
#: responsive while main_steps() take most of the time.
STEP_BUDGET_S = 0.05
STEP_POLL_S = 0.01
#: Seconds above which a button asks before starting a job (runner.forecast()), and a headless
#: run prints the forecast: the issue's budget for an ordinary Build Surfaces.
LONG_JOB_S = 30.0


def status_text(title, p, seconds_left):
    """The status bar's line for JobProgress `p`."""
    if p.total <= 0:
        return f"Plume {title}: {p.label}... (Esc cancels)"
    left = f", ~{seconds_left:.0f} s left" if seconds_left is not None else ""
    return f"Plume {title}: {p.label} {p.done} of {p.total}{left} (Esc cancels)"


def _headless(context):
    """No event loop (``blender -b``, a bpy module, a script without a window)."""
    return bpy.app.background or context.window is None


class JobOperator:
    """Mixin (before bpy.types.Operator) running a JobRunner from make_runner()."""

    def make_runner(self, context):
        """A new JobRunner for this call (properties of the operator passed in)."""
        raise TypeError(f"{type(self).__name__} must define make_runner(context)")

    # ------------------------------------------------------------------ blocking
    def execute(self, context):
        if getattr(self, "_asked", None) is not None and not _headless(context):
            return self._start(context)  # OK in invoke()'s dialog: in the background
        forecast, title = self._long_forecast(context)
        if forecast is not None:  # reports appear when the operator ends: say it now too
            print(f"Plume: {forecast.text(title)}", flush=True)
        runner = self._prepare(context)
        if runner is None:
            return {'CANCELLED'}
        runner.forecast_said = forecast
        error = self._run_child(runner)
        if error is None and not runner.cancelled:
            try:
                for _ in runner.main_steps(context):
                    if runner.cancelled:
                        break
            except Exception as e:
                error = e
        return self._conclude(context, runner, error, None)

    @staticmethod
    def _run_child(runner):
        """Starts the job's child and waits for it (blocking); the error it ended with. Ctrl+C
        in the terminal of a ``blender -b`` script is the job's Esc."""
        try:
            child = JobProcess(runner).start()
        except Exception as e:
            return e
        try:
            child.wait()
        except KeyboardInterrupt:
            runner.cancel()
            child.wait()
        return child.error

    # ------------------------------------------------------------------ in the background
    def invoke(self, context, event):
        if _headless(context):
            return self.execute(context)  # no event loop: modal handlers would never run
        self._forecast, title = self._long_forecast(context)
        self._asked = self._forecast.text(title) if self._forecast is not None else None
        if self._asked is not None:  # OK calls execute() on this same operator
            return context.window_manager.invoke_props_dialog(self, width=420)
        return self._start(context)

    def draw(self, context):
        """The operator's settings (as Blender draws them by default, in the Adjust Last
        Operation panel), under how long the job will take and how to make it shorter while
        the long-job dialog is open."""
        col = self.layout.column()  # the dialog's title is the operator's label already
        if getattr(self, "_asked", None) is not None:
            col.label(text=f"{self._forecast.what}, {self._forecast.about()}", icon='TIME')
            col.label(text="It runs in the background: Esc cancels it.")
            for line in self.make_runner(context).shorter_hint():
                col.label(text=line)
        for prop in self.properties.bl_rna.properties:
            if prop.identifier != "rna_type" and not prop.is_hidden:
                col.prop(self, prop.identifier)

    def _start(self, context):
        """prepare(), then the child with a modal timer (the button's path)."""
        self._asked = None
        runner = self._prepare(context)
        if runner is None:
            return {'CANCELLED'}
        runner.forecast_said = getattr(self, "_forecast", None)
        self._runner, self._steps, self._error, self._gone = runner, None, None, None
        try:
            JobProcess(runner).start()
        except Exception as e:
            return self._conclude(context, runner, e, None)
        wm = context.window_manager
        self._timer = wm.event_timer_add(POLL_S, window=context.window)
        wm.progress_begin(0, 100)
        wm.modal_handler_add(self)
        return {'RUNNING_MODAL'}

    def modal(self, context, event):
        runner = self._runner
        if event.type == 'ESC' and event.value == 'PRESS':
            runner.cancel()
            return {'RUNNING_MODAL'}  # Esc is the job's; nothing else sees it
        if event.type != 'TIMER':
            return {'PASS_THROUGH'}
        if runner.aborted:  # a file load or quit stopped it: nothing to build
            self._end_ui(context)
            registry.release(runner)
            return {'CANCELLED'}
        self._check_objects(runner)
        if not runner.child.poll():
            self._show(context, runner)
            return {'PASS_THROUGH'}
        if not self._main_steps_done(context, runner):
            self._show(context, runner)
            return {'PASS_THROUGH'}
        self._end_ui(context)
        result = self._conclude(context, runner, self._error or runner.child.error, self._gone)
        for area in context.screen.areas if context.screen else ():
            area.tag_redraw()
        return result

    def cancel(self, context):
        """Called by Blender when it drops the modal handler (quit, window closed, file load):
        kill the child and remove what it wrote; the scene is not touched."""
        runner = getattr(self, "_runner", None)
        if runner is None:
            return
        registry.abort(runner)
        try:
            self._end_ui(context)
        except Exception:  # the window may be half torn down already
            pass

    # ------------------------------------------------------------------ parts
    def _long_forecast(self, context):
        """(Forecast, the job's title) when the runner forecasts more than LONG_JOB_S, else
        (None, title) (also when it cannot tell: prepare() reports bad input)."""
        probe = self.make_runner(context)
        try:
            forecast = probe.forecast(context)
        except BakeError:  # bad input: prepare() says so
            forecast = None
        except Exception:  # a forecast never stops a job
            traceback.print_exc()
            forecast = None
        if forecast is None or not forecast.seconds > LONG_JOB_S:
            return None, probe.title
        return forecast, probe.title

    def _prepare(self, context):
        """runner.prepare(); None (the error reported, nothing held) on bad input."""
        runner = self.make_runner(context)
        try:
            runner.prepare(context)
        except runner.prepare_errors as e:
            registry.release(runner)
            self.report({'ERROR'}, runner.refusal_text(e))
            return None
        except BaseException:
            registry.release(runner)
            raise
        return runner

    def _check_objects(self, runner):
        """Cancels the job when an object it works on is gone (deleted, or renamed away from
        the name its cache folder and outputs are keyed by)."""
        if self._gone is not None:
            return
        for name in runner.objects:
            if bpy.data.objects.get(name) is None:
                self._gone = name
                runner.cancel()
                return

    def _main_steps_done(self, context, runner):
        """Runs the runner's main-thread steps for up to STEP_BUDGET_S; True when none are
        left (or the job was cancelled, or failed)."""
        if runner.child.error is not None or self._error is not None or runner.cancelled:
            return True
        if self._steps is None:
            self._steps = runner.main_steps(context)
            wm = context.window_manager  # poll faster: the steps are short and many
            wm.event_timer_remove(self._timer)
            self._timer = wm.event_timer_add(STEP_POLL_S, window=context.window)
        end = time.perf_counter() + STEP_BUDGET_S
        try:
            while time.perf_counter() < end:
                next(self._steps)
                if runner.cancelled:
                    return True
        except StopIteration:
            return True
        except Exception as e:
            self._error = e
            return True
        return False

    def _show(self, context, runner):
        """Status bar and progress cursor from the runner's latest progress."""
        p = runner.progress()
        runner.status_text = status_text(runner.title, p, p.estimate_left(time.perf_counter()))
        if p.total > 0:
            context.window_manager.progress_update(int(100 * p.done / p.total))
        if context.workspace is not None:
            context.workspace.status_text_set(runner.status_text)

    def _end_ui(self, context):
        wm = context.window_manager
        if getattr(self, "_timer", None) is not None:
            wm.event_timer_remove(self._timer)
            self._timer = None
        wm.progress_end()
        if context.workspace is not None:
            context.workspace.status_text_set(None)

    def _conclude(self, context, runner, error, gone):
        """Reports how the job ended; finish() when it succeeded (or a bake was cancelled),
        discard() otherwise. Frees the job's keys. The runner keeps how it ended (`outcome`:
        finished, failed, gone, cancelled) and the report's text (`report_text`)."""
        try:
            if error is not None:
                runner.discard()
                return self._end_report(runner, 'failed', 'ERROR',
                                        runner.no_room_text(error) or runner.error_text(error))
            if gone is not None:
                runner.discard()
                return self._end_report(runner, 'gone', 'WARNING',
                                        f"Plume: {runner.title} cancelled: object '{gone}' was "
                                        "deleted or renamed; nothing was built")
            if runner.cancelled and (runner.killed or not runner.keeps_partial):
                runner.discard()
                return self._end_report(runner, 'cancelled', 'WARNING', runner.cancelled_text())
            try:
                kind, text = runner.finish(context)
            except Exception as e:
                if not isinstance(e, BakeError):
                    traceback.print_exc()
                runner.discard()
                return self._end_report(runner, 'failed', 'ERROR',
                                        runner.no_room_text(e) or runner.error_text(e))
            if runner.forecast_said is not None:
                text += f" (forecast: {runner.forecast_said.about()})"
            self._end_report(runner, 'cancelled' if runner.cancelled else 'finished', kind, text)
            return {'FINISHED'}
        finally:
            registry.release(runner)

    def _end_report(self, runner, outcome, kind, text):
        """Reports `text`; {'CANCELLED'} (the callers that built nothing return it)."""
        runner.outcome, runner.report_text = outcome, text
        self.report({kind}, text)
        return {'CANCELLED'}
