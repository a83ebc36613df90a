//! Subcommand options that are defined only when their subcommand runs, so that start-up
//! builds the options of one subcommand rather than of all of them.

use std::ops::Deref;

use clap::{ArgMatches, Args, Command, FromArgMatches};

/// The options `T` of one subcommand, added to the command line only once that
/// subcommand is chosen (clap's [`Command::defer`]); reads as a `T`.
pub struct Deferred<T>(T);

impl<T> Deref for Deferred<T> {
    type Target = T;

    fn deref(&self) -> &T {
        &self.0
    }
}

impl<T: FromArgMatches> FromArgMatches for Deferred<T> {
    fn from_arg_matches(matches: &ArgMatches) -> Result<Self, clap::Error> {
        T::from_arg_matches(matches).map(Deferred)
    }

    fn update_from_arg_matches(&mut self, matches: &ArgMatches) -> Result<(), clap::Error> {
        self.0.update_from_arg_matches(matches)
    }
}

impl<T: Args> Args for Deferred<T> {
    fn augment_args(cmd: Command) -> Command {
        cmd.defer(|cmd| keep_about(cmd, T::augment_args))
    }

    fn augment_args_for_update(cmd: Command) -> Command {
        cmd.defer(|cmd| keep_about(cmd, T::augment_args_for_update))
    }
}

/// Adds options with `augment`, keeping the subcommand's own description: the one written
/// on the subcommand, not the one on its options' type.
fn keep_about(cmd: Command, augment: fn(Command) -> Command) -> Command {
    let about = cmd.get_about().cloned();
    let long_about = cmd.get_long_about().cloned();
    let cmd = augment(cmd);
    let cmd = match about {
        Some(a) => cmd.about(a),
        None => cmd.about(None::<&str>),
    };
    match long_about {
        Some(a) => cmd.long_about(a),
        None => cmd.long_about(None::<&str>),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    /// Options of a subcommand in a test command line.
    #[derive(Args)]
    struct Opts {
        /// A count.
        #[arg(long, default_value_t = 1)]
        count: u32,
    }

    #[derive(clap::Subcommand)]
    enum Sub {
        /// Counts things.
        Count(Deferred<Opts>),
    }

    #[derive(Parser)]
    struct Line {
        #[command(subcommand)]
        sub: Sub,
    }

    /// A deferred subcommand has no options until it is built; then it has its options,
    /// keeps its own description, and parses as the plain options would.
    #[test]
    fn options_come_when_the_subcommand_is_built() {
        let mut cmd = <Line as clap::CommandFactory>::command();
        let count = cmd.find_subcommand("count").unwrap();
        assert_eq!(count.get_arguments().count(), 0);
        cmd.build();
        let count = cmd.find_subcommand("count").unwrap();
        assert!(count.get_arguments().any(|a| a.get_id() == "count"));
        assert_eq!(count.get_about().unwrap().to_string(), "Counts things");
        let Sub::Count(opts) = Line::try_parse_from(["t", "count", "--count", "7"])
            .unwrap()
            .sub;
        assert_eq!(opts.count, 7);
        assert!(Line::try_parse_from(["t", "count", "--bogus"]).is_err());
    }
}
