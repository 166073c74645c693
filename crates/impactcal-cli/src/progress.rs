//! Progress of a study or a loop on standard error. On a terminal: an overall bar (runs
//! done of runs planned, the time left) over a bar for the stage that runs, its name in
//! words, each stage's start printed above them. Elsewhere (a log, `nohup`): a plain line
//! at each stage and step, and every `IMPACTCAL_PROGRESS_SECONDS` seconds (30 by default)
//! while a stage runs. The bars are cleared before the results are printed.

use std::io::IsTerminal;
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::time::{Duration, Instant};

use impactcal::calibrate::progress::stage_title;
use impactcal::calibrate::study::Observer;
use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};

/// Seconds between plain lines while a stage runs, when stderr is not a terminal.
const INTERVAL_VARIABLE: &str = "IMPACTCAL_PROGRESS_SECONDS";
const DEFAULT_INTERVAL: Duration = Duration::from_secs(30);

/// The counts behind the display: runs planned and done over the whole computation and in
/// the current stage, and the runs made in this process (not read from the journal), from
/// which the time left is estimated. A count never passes its total: a total is raised to
/// the count when more runs finish than were announced.
#[derive(Debug, Clone)]
pub struct Tracker {
    started: Instant,
    planned: usize,
    done: usize,
    ran: usize,
    reuse_left: usize,
    stage: Option<Stage>,
    last_line: Instant,
    interval: Duration,
}

/// The stage of runs under way.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Stage {
    /// Its name in words.
    pub title: String,
    /// Its runs.
    pub total: usize,
    /// Its runs finished.
    pub done: usize,
    /// Its runs read back from the journal.
    pub reused: usize,
}

impl Tracker {
    /// A tracker started at `now` that asks for a plain line every `interval`.
    pub fn new(now: Instant, interval: Duration) -> Tracker {
        Tracker {
            started: now,
            planned: 0,
            done: 0,
            ran: 0,
            reuse_left: 0,
            stage: None,
            last_line: now,
            interval,
        }
    }

    /// The whole computation is estimated at `runs` runs (never fewer than those done).
    pub fn plan(&mut self, runs: usize) {
        self.planned = runs.max(self.done);
    }

    /// A stage of `total` runs, `reused` of them from the journal, starts.
    pub fn stage(&mut self, name: &str, total: usize, reused: usize, now: Instant) {
        self.stage = Some(Stage {
            title: stage_title(name),
            total,
            done: 0,
            reused,
        });
        self.reuse_left = reused;
        self.planned = self.planned.max(self.done + total);
        self.last_line = now;
    }

    /// A further part of the current stage starts, `reused` of its runs from the journal.
    pub fn part(&mut self, reused: usize) {
        self.reuse_left += reused;
        if let Some(s) = self.stage.as_mut() {
            s.reused += reused;
        }
    }

    /// A step without runs starts: no stage of runs is under way any more.
    pub fn step(&mut self, now: Instant) {
        self.stage = None;
        self.last_line = now;
    }

    /// One more run finished.
    pub fn run_finished(&mut self) {
        self.done += 1;
        self.planned = self.planned.max(self.done);
        if self.reuse_left > 0 {
            self.reuse_left -= 1;
        } else {
            self.ran += 1;
        }
        if let Some(s) = self.stage.as_mut() {
            s.done += 1;
            s.total = s.total.max(s.done);
        }
    }

    /// Runs done and runs planned.
    pub fn overall(&self) -> (usize, usize) {
        (self.done, self.planned)
    }

    /// The stage of runs under way.
    pub fn current(&self) -> Option<&Stage> {
        self.stage.as_ref()
    }

    /// The time left at `now`: the runs left at the mean time per run made so far (the
    /// steps between stages included); `None` before a run was made here.
    pub fn time_left(&self, now: Instant) -> Option<Duration> {
        if self.ran == 0 {
            return None;
        }
        let per_run = now.saturating_duration_since(self.started).as_secs_f64() / self.ran as f64;
        let left = self.planned.saturating_sub(self.done) as f64 * per_run;
        Some(Duration::from_secs_f64(left))
    }

    /// "12/130 runs, about 4 min left".
    pub fn summary(&self, now: Instant) -> String {
        let (done, planned) = self.overall();
        match self.time_left(now) {
            Some(t) if done < planned => format!("{done}/{planned} runs, {}", left(t)),
            _ => format!("{done}/{planned} runs"),
        }
    }

    /// `text` after the overall counts in brackets, "[3/130 runs, about 4 min left] text";
    /// `text` alone before anything was planned or run.
    pub fn with_counts(&self, now: Instant, text: &str) -> String {
        if self.overall() == (0, 0) {
            return text.to_string();
        }
        let head = format!("[{}]", self.summary(now));
        if text.is_empty() {
            head
        } else {
            format!("{head} {text}")
        }
    }

    /// The plain line of the stage under way at `now`, e.g. "[3/130 runs, about 4 min
    /// left] calibration, CORS-RBF search: 2/24 runs (1 from the journal)".
    pub fn line(&self, now: Instant) -> String {
        let text = match &self.stage {
            Some(s) => {
                let reuse = if s.reused > 0 {
                    format!(" ({} from the journal)", s.reused)
                } else {
                    String::new()
                };
                format!("{}: {}/{} runs{reuse}", s.title, s.done, s.total)
            }
            None => String::new(),
        };
        self.with_counts(now, &text)
    }

    /// Ends the computation at `now`: nothing is under way, the runs planned are those
    /// done. Returns `now`.
    pub fn end(&mut self) -> Instant {
        let now = Instant::now();
        self.stage = None;
        self.planned = self.done;
        now
    }

    /// The last line: "[213/213 runs] in 1 min".
    pub fn final_line(&self, now: Instant) -> String {
        format!(
            "[{}] in {}",
            self.summary(now),
            duration(now.saturating_duration_since(self.started))
        )
    }

    /// The periodic line, when a stage of runs is under way and `interval` has passed
    /// since the last line; the time of the last line is then `now`.
    pub fn tick(&mut self, now: Instant) -> Option<String> {
        if self.stage.is_none() || now.saturating_duration_since(self.last_line) < self.interval {
            return None;
        }
        self.last_line = now;
        Some(self.line(now))
    }
}

/// The time left as a person says it: "about 4 min left", "under 1 s left".
fn left(t: Duration) -> String {
    if t < Duration::from_secs(1) {
        "under 1 s left".to_string()
    } else {
        format!("about {} left", duration(t))
    }
}

/// A duration as a person reads it: "under 1 s", "40 s", "4 min", "1 h 05 min".
fn duration(t: Duration) -> String {
    let s = t.as_secs();
    if s == 0 {
        "under 1 s".to_string()
    } else if s < 60 {
        format!("{s} s")
    } else if s < 3600 {
        format!("{} min", (s + 30) / 60)
    } else {
        format!("{} h {:02} min", s / 3600, (s % 3600) / 60)
    }
}

/// The bars of a terminal.
struct Bars {
    multi: MultiProgress,
    overall: ProgressBar,
    stage: ProgressBar,
}

struct Shared {
    tracker: Mutex<Tracker>,
    stop: Mutex<bool>,
    wake: Condvar,
}

impl Shared {
    fn tracker(&self) -> MutexGuard<'_, Tracker> {
        self.tracker.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// Progress on this process's stderr (see the module docs).
pub struct Progress {
    shared: Arc<Shared>,
    bars: Option<Bars>,
    ticker: Option<std::thread::JoinHandle<()>>,
}

impl Progress {
    /// A progress display for this process's stderr.
    pub fn new() -> Progress {
        let interval = std::env::var(INTERVAL_VARIABLE)
            .ok()
            .and_then(|v| v.trim().parse::<f64>().ok())
            .filter(|s| s.is_finite() && *s > 0.0)
            .map_or(DEFAULT_INTERVAL, Duration::from_secs_f64);
        let shared = Arc::new(Shared {
            tracker: Mutex::new(Tracker::new(Instant::now(), interval)),
            stop: Mutex::new(false),
            wake: Condvar::new(),
        });
        if std::io::stderr().is_terminal() {
            return Progress {
                shared,
                bars: Some(bars()),
                ticker: None,
            };
        }
        let ticking = Arc::clone(&shared);
        let ticker = std::thread::spawn(move || tick_until_stopped(&ticking, interval));
        Progress {
            shared,
            bars: None,
            ticker: Some(ticker),
        }
    }

    /// Clears the bars (or stops the periodic lines after a last line, "[213/213 runs] in
    /// 1 min"): what is printed next starts on a line of its own. Runs still planned then
    /// are not made: the runs planned become the runs done.
    pub fn done(&self) {
        if self.closed() {
            return;
        }
        let last = {
            let mut t = self.shared.tracker();
            let end = t.end();
            (t.overall().0 > 0).then(|| t.final_line(end))
        };
        if let (None, Some(line)) = (&self.bars, last) {
            eprintln!("impactcal: {line}");
        }
        if let Some(b) = &self.bars {
            b.stage.finish_and_clear();
            b.overall.finish_and_clear();
            let _ = b.multi.clear();
        }
        if let Ok(mut stop) = self.shared.stop.lock() {
            *stop = true;
        }
        self.shared.wake.notify_all();
    }

    fn closed(&self) -> bool {
        self.shared.stop.lock().map_or(true, |s| *s)
    }

    fn say(&self, line: &str) {
        match &self.bars {
            Some(b) => {
                let _ = b.multi.println(format!("impactcal: {line}"));
            }
            None => eprintln!("impactcal: {line}"),
        }
    }

    fn redraw(&self, tracker: &Tracker) {
        let Some(b) = &self.bars else { return };
        let now = Instant::now();
        let (done, planned) = tracker.overall();
        b.overall.set_length(planned as u64);
        b.overall.set_position(done as u64);
        b.overall.set_message(match tracker.time_left(now) {
            Some(t) if done < planned => format!(", {}", left(t)),
            _ => String::new(),
        });
        match tracker.current() {
            Some(s) => {
                b.stage.set_length(s.total as u64);
                b.stage.set_position(s.done as u64);
                b.stage.set_message(s.title.clone());
            }
            None => {
                b.stage.set_length(0);
                b.stage.set_position(0);
            }
        }
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        self.done();
        if let Some(t) = self.ticker.take() {
            let _ = t.join();
        }
    }
}

fn bars() -> Bars {
    let multi = MultiProgress::with_draw_target(ProgressDrawTarget::stderr());
    let style = |template: &str| {
        ProgressStyle::with_template(template)
            .map(|s| s.progress_chars("=> "))
            .unwrap_or_else(|_| ProgressStyle::default_bar())
    };
    let overall = multi.add(ProgressBar::new(0));
    overall.set_style(style(
        "overall [{bar:30}] {pos}/{len} runs, {elapsed} so far{msg}",
    ));
    // The elapsed time moves while a long run holds every count still.
    overall.enable_steady_tick(Duration::from_secs(1));
    let stage = multi.add(ProgressBar::new(0));
    stage.set_style(style("  stage [{bar:30}] {pos}/{len} runs: {msg}"));
    Bars {
        multi,
        overall,
        stage,
    }
}

/// Prints the periodic line until `done`.
fn tick_until_stopped(shared: &Shared, interval: Duration) {
    let period = interval.min(Duration::from_secs(1));
    let mut stop = shared.stop.lock().unwrap_or_else(|e| e.into_inner());
    while !*stop {
        stop = match shared.wake.wait_timeout(stop, period) {
            Ok((s, _)) => s,
            Err(e) => e.into_inner().0,
        };
        if *stop {
            break;
        }
        if let Some(line) = shared.tracker().tick(Instant::now()) {
            eprintln!("impactcal: {line}");
        }
    }
}

impl Observer for Progress {
    fn plan(&self, runs: usize) {
        let mut t = self.shared.tracker();
        t.plan(runs);
        self.redraw(&t);
    }

    fn stage(&self, name: &str, total: usize, reused: usize) {
        let mut t = self.shared.tracker();
        let now = Instant::now();
        t.stage(name, total, reused, now);
        let line = t.line(now);
        self.say(&line);
        self.redraw(&t);
    }

    fn part(&self, reused: usize) {
        let mut t = self.shared.tracker();
        t.part(reused);
        self.redraw(&t);
    }

    fn run_finished(&self) {
        let mut t = self.shared.tracker();
        t.run_finished();
        self.redraw(&t);
    }

    fn warning(&self, text: &str) {
        self.say(&format!("warning: {text}"));
    }

    fn step(&self, name: &str) {
        let mut t = self.shared.tracker();
        let now = Instant::now();
        t.step(now);
        let line = t.with_counts(now, name);
        self.say(&line);
        self.redraw(&t);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// An event an observer receives.
    #[derive(Debug, Clone)]
    enum Event {
        Plan(usize),
        Stage(usize, usize),
        Part(usize),
        Run,
        Step,
    }

    fn event() -> impl Strategy<Value = Event> {
        prop_oneof![
            (0usize..50).prop_map(Event::Plan),
            (0usize..10, 0usize..10).prop_map(|(t, r)| Event::Stage(t, r)),
            (0usize..5).prop_map(Event::Part),
            Just(Event::Run),
            Just(Event::Run),
            Just(Event::Run),
            Just(Event::Step),
        ]
    }

    proptest! {
        /// Whatever the order of stages, parts, plans and finished runs (more runs than
        /// announced included, as a stage run in parts may report), no count passes its
        /// total, the overall count is the runs finished, and the time left is finite.
        #[test]
        fn no_bar_passes_its_total(events in proptest::collection::vec(event(), 0..80)) {
            let t0 = Instant::now();
            let mut t = Tracker::new(t0, Duration::from_secs(30));
            let mut runs = 0;
            for (k, e) in events.iter().enumerate() {
                let now = t0 + Duration::from_secs(k as u64);
                match *e {
                    Event::Plan(n) => t.plan(n),
                    Event::Stage(total, reused) => t.stage("r0-cors", total, reused, now),
                    Event::Part(r) => t.part(r),
                    Event::Run => {
                        t.run_finished();
                        runs += 1;
                    }
                    Event::Step => t.step(now),
                }
                let (done, planned) = t.overall();
                prop_assert_eq!(done, runs);
                prop_assert!(done <= planned, "{done}/{planned}");
                if let Some(s) = t.current() {
                    prop_assert!(s.done <= s.total, "{}/{}", s.done, s.total);
                }
                if let Some(left) = t.time_left(now) {
                    prop_assert!(left.as_secs_f64().is_finite());
                }
            }
        }
    }

    /// The CORS stage of a loop announced with its budget of 24 and run in 6 parts of 4:
    /// 24/24 at the end, never 24/4; runs read from the journal do not count towards the
    /// time per run.
    #[test]
    fn a_stage_in_parts_counts_to_its_budget() {
        let t0 = Instant::now();
        let mut t = Tracker::new(t0, Duration::from_secs(30));
        t.plan(30);
        t.stage("r0-cors", 24, 0, t0);
        for part in 0..6 {
            t.part(if part == 0 { 2 } else { 0 });
            for _ in 0..4 {
                t.run_finished();
            }
        }
        let s = t.current().cloned();
        assert_eq!(
            s,
            Some(Stage {
                title: "calibration, CORS-RBF search".into(),
                total: 24,
                done: 24,
                reused: 2,
            })
        );
        // 22 runs made in 44 s: 2 s a run, 6 runs left.
        let left = t.time_left(t0 + Duration::from_secs(44));
        assert_eq!(left, Some(Duration::from_secs(12)));
        assert_eq!(
            t.line(t0 + Duration::from_secs(44)),
            "[24/30 runs, about 12 s left] calibration, CORS-RBF search: 24/24 runs \
             (2 from the journal)"
        );
    }

    /// A plain line every interval while a stage runs, none between stages.
    #[test]
    fn periodic_lines_come_every_interval_during_a_stage() {
        let t0 = Instant::now();
        let at = |s: u64| t0 + Duration::from_secs(s);
        let mut t = Tracker::new(t0, Duration::from_secs(30));
        t.plan(10);
        t.stage("noise", 8, 0, at(0));
        assert_eq!(t.tick(at(29)), None);
        t.run_finished();
        assert_eq!(
            t.tick(at(30)).as_deref(),
            Some("[1/10 runs, about 5 min left] jitter ensemble (the model's own noise): 1/8 runs")
        );
        assert_eq!(t.tick(at(45)), None);
        assert!(t.tick(at(60)).is_some());
        t.step(at(61));
        assert_eq!(t.tick(at(200)), None);
    }

    #[test]
    fn durations_read_as_a_person_says_them() {
        assert_eq!(duration(Duration::from_millis(300)), "under 1 s");
        assert_eq!(duration(Duration::from_secs(42)), "42 s");
        assert_eq!(duration(Duration::from_secs(250)), "4 min");
        assert_eq!(duration(Duration::from_secs(3900)), "1 h 05 min");
    }
}
