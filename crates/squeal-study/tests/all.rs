//! The squeal-study integration tests as one binary (one link and one copy of the
//! library's generic code instead of one per file: issue 24, class 9).
//! Each file of this folder is a module; a new test file is declared here.

mod library;
mod run_many;
mod slow_growth;
mod validate;
