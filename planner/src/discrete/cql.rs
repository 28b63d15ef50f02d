//! Contextual Q-learning (the paper's Algorithm 3, equations 10 and 11) and
//! the plain Q-learning baseline, sharing one tabular training loop.
//!
//! - Equation (10): the agent acts by the masked argmax of
//!   (Q + |min Q|) ⊙ ζ. Adding |min Q| only shifts a state's values, so this
//!   is the argmax over afforded actions; ties are broken at random. With
//!   probability ε it instead samples an afforded action in proportion to its
//!   (shifted) Q-value, as the authors' code does.
//! - Equation (11): Q(s,a) ← Q(s,a) + α [r + γ max_{a' afforded} Q(s',a') − Q(s,a)];
//!   a terminal transition (DROP) sets Q(s,a) ← r.
//! - After each episode its transitions are replayed once in reverse order
//!   with the same update (reverse experience replay), so a reward reached at
//!   the end of an episode propagates back to the start in one sweep instead
//!   of one step per episode. The authors' scheme without it fails on long
//!   tasks (see `docs/decisions.md`); set `replay: false` for the literal one.
//! - Schedule: until some episode first reaches the goal the agent acts
//!   greedily on its values and the episode never restarts (`optimistic_search`).
//!   Values it has tried decay below the untried contextual values, so the
//!   greedy agent always heads for the nearest untried promising action: a
//!   real-time search (LRTA*-like) that reaches any reachable goal. After
//!   that, ε-exploration refines the plan and episodes restart from the start
//!   every `episode_steps`. The authors restart every 150 steps from the
//!   first step, which starves long detours (see `docs/decisions.md`).
//! - Training stops when the greedy rollout (checked after every episode)
//!   completes the task and has stayed the same for `convergence_window`
//!   consecutive checks, or when the step budget runs out.
//!
//! Plain Q-learning (the paper's QL baseline) starts from a zero table, sees
//! no affordance mask and explores uniformly; an action the scene does not
//! afford earns `reward_refused` and leaves the agent where it was.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::affordance::{Affordances, contextual_q_table};
use crate::error::FieldIssue;
use crate::task::{Action, AgentState, GridTask, Outcome};

/// Learning parameters. Every field has a default, written once in
/// [`Default`]; a scenario's `learner:` section may override any of them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LearnerSettings {
    /// α, the learning rate. Default 1: the grid task is deterministic, so
    /// the full step is the exact backup. The authors use 0.05 (the paper
    /// prints it as "γ = 0.05": the names are swapped).
    pub learning_rate: f64,
    /// γ, the discount. The paper prints "α = 0.99" (names swapped).
    pub discount: f64,
    /// ε: probability of an exploratory (Q-proportional) action once the
    /// goal has been reached (see `optimistic_search`).
    pub epsilon: f64,
    /// ζ's value for an afforded action in the initial table (eq. 9).
    pub affordance_value: f64,
    /// ξ: bonus for a move that reduces the distance to the sub-target (eq. 9).
    pub distance_bias: f64,
    /// Reward for a displacement.
    pub reward_move: f64,
    /// Reward for GRASP.
    pub reward_grasp: f64,
    /// Reward for GOAL (entering the goal; not terminal).
    pub reward_goal: f64,
    /// Reward for the terminal DROP in the goal.
    pub reward_drop: f64,
    /// Reward for an action the scene does not afford (plain QL only: CQL
    /// never takes one).
    pub reward_refused: f64,
    /// Training budget in environment steps.
    pub max_steps: usize,
    /// Steps before an episode restarts from the start; 0 = automatic,
    /// 4·(n + m) + 16, long enough for any simple path around the grid.
    pub episode_steps: usize,
    /// Replay each episode in reverse after it ends.
    pub replay: bool,
    /// Until an episode first reaches the goal, act greedily on the
    /// (optimistic) values and never restart: a real-time search in the
    /// manner of LRTA*, which cannot fail to reach a reachable goal. ε-
    /// exploration and episode restarts start after that.
    pub optimistic_search: bool,
    /// Consecutive identical successful greedy rollouts that count as converged.
    pub convergence_window: usize,
}

impl Default for LearnerSettings {
    fn default() -> Self {
        Self {
            learning_rate: 1.0,
            discount: 0.99,
            epsilon: 0.3,
            affordance_value: 1.0,
            distance_bias: 0.1,
            reward_move: 0.0,
            reward_grasp: 0.0,
            reward_goal: 10.0,
            reward_drop: 10.0,
            reward_refused: -1.0,
            max_steps: 100_000,
            episode_steps: 0,
            replay: true,
            optimistic_search: true,
            convergence_window: 100,
        }
    }
}

impl LearnerSettings {
    /// The authors' literal scheme (learning rate 0.05, 10,000 steps, restart
    /// every 150 steps, always Q-proportional sampling, no replay).
    pub fn paper() -> Self {
        Self {
            learning_rate: 0.05,
            epsilon: 1.0,
            max_steps: 10_000,
            episode_steps: 150,
            replay: false,
            optimistic_search: false,
            ..Self::default()
        }
    }

    /// Steps before an episode restarts from the start on `task`:
    /// `episode_steps`, or 4·(n + m) + 16 when it is 0 (automatic).
    pub fn episode_length(&self, task: &GridTask) -> usize {
        match self.episode_steps {
            0 => 4 * (task.grid.rows + task.grid.cols) + 16,
            n => n,
        }
    }

    /// The reward r(s, a) of taking `a` with the given outcome: the terminal
    /// DROP, a refused action (plain QL only: the agent stays), GRASP, GOAL
    /// or a displacement.
    pub fn reward(&self, a: Action, outcome: Outcome) -> f64 {
        match (outcome, a) {
            (Outcome::Done, _) => self.reward_drop,
            (Outcome::Refused, _) => self.reward_refused,
            (Outcome::Moved(_), Action::Grasp) => self.reward_grasp,
            (Outcome::Moved(_), Action::Goal) => self.reward_goal,
            (Outcome::Moved(_), _) => self.reward_move,
        }
    }

    /// Problems with the settings, field names relative to the struct.
    pub fn validate(&self) -> Vec<FieldIssue> {
        let mut issues = Vec::new();
        let unit = [
            ("learning_rate", self.learning_rate),
            ("discount", self.discount),
            ("epsilon", self.epsilon),
        ];
        for (name, v) in unit {
            if !(v.is_finite() && (0.0..=1.0).contains(&v)) {
                issues.push(FieldIssue::new(
                    name,
                    format!("must be between 0 and 1, got {v}"),
                ));
            }
        }
        if self.learning_rate == 0.0 {
            issues.push(FieldIssue::new("learning_rate", "must be greater than 0"));
        }
        let finite = [
            ("affordance_value", self.affordance_value),
            ("distance_bias", self.distance_bias),
            ("reward_move", self.reward_move),
            ("reward_grasp", self.reward_grasp),
            ("reward_goal", self.reward_goal),
            ("reward_drop", self.reward_drop),
            ("reward_refused", self.reward_refused),
        ];
        for (name, v) in finite {
            if !v.is_finite() {
                issues.push(FieldIssue::new(
                    name,
                    format!("must be a finite number, got {v}"),
                ));
            }
        }
        if self.max_steps == 0 {
            issues.push(FieldIssue::new("max_steps", "must be at least 1"));
        }
        if self.convergence_window == 0 {
            issues.push(FieldIssue::new("convergence_window", "must be at least 1"));
        }
        issues
    }
}

/// The learned plan of one grid task.
#[derive(Debug, Clone, PartialEq)]
pub struct LearnedPlan {
    /// Greedy rollout's actions; complete only when `solved`.
    pub actions: Vec<Action>,
    /// `cells[0]` is the start; `cells[k + 1]` is where action k left the
    /// gripper (GRASP and DROP leave it where it was).
    pub cells: Vec<(usize, usize)>,
    /// The greedy rollout ends with DROP in the goal, using afforded actions only.
    pub solved: bool,
    /// Environment steps spent training.
    pub training_steps: usize,
    /// Training stopped on a stable greedy rollout rather than the budget.
    pub converged: bool,
}

/// Which of the two learners runs the shared loop.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Variant {
    Contextual,
    Plain,
}

/// Contextual Q-learning: affordance masks and optimistic contextual initial
/// values (equations 8–11, Algorithm 3).
#[derive(Debug, Clone)]
pub struct ContextualQLearner {
    pub settings: LearnerSettings,
}

/// Plain tabular Q-learning, the paper's QL baseline.
#[derive(Debug, Clone)]
pub struct QLearner {
    pub settings: LearnerSettings,
}

impl ContextualQLearner {
    pub fn new(settings: LearnerSettings) -> Self {
        Self { settings }
    }

    /// Learns a plan for `task`; `seed` fixes every random choice.
    pub fn learn(&self, task: &GridTask, seed: u64) -> LearnedPlan {
        Training::new(task, &self.settings, Variant::Contextual, seed).run()
    }
}

impl QLearner {
    pub fn new(settings: LearnerSettings) -> Self {
        Self { settings }
    }

    pub fn learn(&self, task: &GridTask, seed: u64) -> LearnedPlan {
        Training::new(task, &self.settings, Variant::Plain, seed).run()
    }
}

/// Scratch state of one training run.
struct Training<'a> {
    task: &'a GridTask,
    settings: &'a LearnerSettings,
    variant: Variant,
    zeta: Affordances,
    q: Vec<f64>,
    rng: ChaCha8Rng,
    episode: Vec<(usize, Action, f64, Option<usize>)>,
    /// Some episode has reached the terminal DROP.
    reached_goal: bool,
}

const ALL_ACTIONS: u8 = (1 << Action::COUNT) - 1;

impl<'a> Training<'a> {
    fn new(task: &'a GridTask, settings: &'a LearnerSettings, variant: Variant, seed: u64) -> Self {
        let zeta = Affordances::of(task);
        let q = match variant {
            Variant::Contextual => contextual_q_table(
                task,
                &zeta,
                settings.affordance_value,
                settings.distance_bias,
            ),
            Variant::Plain => vec![0.0; task.state_count() * Action::COUNT],
        };
        Self {
            task,
            settings,
            variant,
            zeta,
            q,
            rng: ChaCha8Rng::seed_from_u64(seed),
            episode: Vec::new(),
            reached_goal: false,
        }
    }

    fn run(mut self) -> LearnedPlan {
        let episode_steps = self.settings.episode_length(self.task);
        let (mut steps, mut stable, mut converged) = (0, 0, false);
        let mut previous: Option<Vec<Action>> = None;
        while steps < self.settings.max_steps && !converged {
            let limit = if self.searching() {
                self.settings.max_steps
            } else {
                episode_steps
            };
            steps += self.run_episode(limit.min(self.settings.max_steps - steps));
            if self.settings.replay {
                self.replay();
            }
            let rollout = self.greedy_rollout();
            stable = match (&previous, rollout.solved) {
                (_, false) => 0,
                (Some(prev), true) if *prev == rollout.actions => stable + 1,
                _ => 1,
            };
            converged = stable >= self.settings.convergence_window;
            previous = rollout.solved.then_some(rollout.actions);
        }
        LearnedPlan {
            training_steps: steps,
            converged,
            ..self.greedy_rollout()
        }
    }

    /// One episode from the start; returns the steps taken.
    fn run_episode(&mut self, limit: usize) -> usize {
        self.episode.clear();
        let mut s = self.task.start();
        for t in 0..limit {
            let i = self.task.state_index(s);
            let a = self.select(i);
            let (r, next) = self.transition(s, a);
            let next_index = next.map(|n| self.task.state_index(n));
            self.update(i, a, r, next_index);
            self.episode.push((i, a, r, next_index));
            match next {
                Some(n) => s = n,
                None => {
                    self.reached_goal = true;
                    return t + 1;
                }
            }
        }
        limit
    }

    /// Reward and next state; `None` after the terminal DROP.
    fn transition(&self, s: AgentState, a: Action) -> (f64, Option<AgentState>) {
        let outcome = self.task.step(s, a);
        let next = match outcome {
            Outcome::Done => None,
            Outcome::Refused => Some(s),
            Outcome::Moved(next) => Some(next),
        };
        (self.settings.reward(a, outcome), next)
    }

    /// Equation (11), or Q ← r on the terminal transition.
    fn update(&mut self, i: usize, a: Action, r: f64, next: Option<usize>) {
        let k = i * Action::COUNT + a.index();
        self.q[k] = match next {
            None => r,
            Some(j) => {
                let target = r + self.settings.discount * self.best(j).1;
                self.q[k] + self.settings.learning_rate * (target - self.q[k])
            }
        };
    }

    fn replay(&mut self) {
        let episode = std::mem::take(&mut self.episode);
        for &(i, a, r, next) in episode.iter().rev() {
            self.update(i, a, r, next);
        }
        self.episode = episode;
    }

    /// In the search phase: optimistic search is on and no episode has
    /// reached the goal yet.
    fn searching(&self) -> bool {
        self.settings.optimistic_search && !self.reached_goal
    }

    /// Actions the learner may choose in state `i`.
    fn choices(&self, i: usize) -> u8 {
        match self.variant {
            Variant::Contextual => self.zeta.mask(i),
            Variant::Plain => ALL_ACTIONS,
        }
    }

    /// Best action and its value among the choices (equation 10); ties go to
    /// the lowest action index.
    fn best(&self, i: usize) -> (Option<Action>, f64) {
        let mask = self.choices(i);
        let row = &self.q[i * Action::COUNT..(i + 1) * Action::COUNT];
        Action::ALL
            .into_iter()
            .filter(|a| mask & (1 << a.index()) != 0)
            .fold((None, f64::NEG_INFINITY), |(ba, bv), a| {
                if row[a.index()] > bv {
                    (Some(a), row[a.index()])
                } else {
                    (ba, bv)
                }
            })
    }

    /// ε-greedy choice: exploration samples afforded actions in proportion to
    /// their shifted Q-value (CQL) or uniformly (QL); exploitation is the
    /// masked argmax with random tie-breaking.
    fn select(&mut self, i: usize) -> Action {
        let mask = self.choices(i);
        let row = &self.q[i * Action::COUNT..(i + 1) * Action::COUNT];
        let allowed = |a: &Action| mask & (1 << a.index()) != 0;
        let explore = !self.searching() && self.rng.random::<f64>() < self.settings.epsilon;
        let mut weights = [0.0; Action::COUNT];
        if explore {
            let min = Action::ALL
                .iter()
                .filter(|a| allowed(a))
                .map(|a| row[a.index()])
                .fold(0.0, f64::min);
            for a in Action::ALL.iter().filter(|a| allowed(a)) {
                weights[a.index()] = match self.variant {
                    Variant::Contextual => row[a.index()] - min + 1e-9,
                    Variant::Plain => 1.0,
                };
            }
        } else {
            let max = Action::ALL
                .iter()
                .filter(|a| allowed(a))
                .map(|a| row[a.index()])
                .fold(f64::NEG_INFINITY, f64::max);
            for a in Action::ALL
                .iter()
                .filter(|a| allowed(a) && row[a.index()] >= max)
            {
                weights[a.index()] = 1.0;
            }
        }
        self.sample(&weights)
    }

    /// Draws an action with probability proportional to its weight.
    fn sample(&mut self, weights: &[f64; Action::COUNT]) -> Action {
        let total: f64 = weights.iter().sum();
        let mut x = self.rng.random::<f64>() * total;
        let mut last = Action::Up;
        for a in Action::ALL.into_iter().filter(|a| weights[a.index()] > 0.0) {
            if x < weights[a.index()] {
                return a;
            }
            x -= weights[a.index()];
            last = a;
        }
        last
    }

    /// Follows the masked argmax from the start until DROP, a refused action
    /// or a repeated state (a greedy policy that repeats a state loops).
    fn greedy_rollout(&self) -> LearnedPlan {
        let mut visited = vec![false; self.task.state_count()];
        let mut s = self.task.start();
        let mut plan = LearnedPlan {
            actions: Vec::new(),
            cells: vec![s.cell],
            solved: false,
            training_steps: 0,
            converged: false,
        };
        loop {
            let i = self.task.state_index(s);
            if std::mem::replace(&mut visited[i], true) {
                return plan;
            }
            let Some(a) = self.best(i).0 else { return plan };
            plan.actions.push(a);
            match self.task.step(s, a) {
                Outcome::Done => {
                    plan.solved = true;
                    plan.cells.push(s.cell);
                    return plan;
                }
                Outcome::Refused => return plan,
                Outcome::Moved(next) => {
                    s = next;
                    plan.cells.push(s.cell);
                }
            }
        }
    }
}
