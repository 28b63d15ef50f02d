pub use afford_planner as planner;
