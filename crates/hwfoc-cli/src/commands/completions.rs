//! `hwfoc completions SHELL`: the shell's completion script for every command and option,
//! generated from the command line's own definitions (clap_complete), so it never lags behind.

use clap::Args;
use clap_complete::Shell;

use crate::error::CliError;
use crate::output::TextSink;

const AFTER_HELP: &str = "\
Load it for the running shell, or install it where the shell finds it:
  source <(hwfoc completions bash)
  hwfoc completions bash > ~/.local/share/bash-completion/completions/hwfoc
  hwfoc completions zsh > ~/.zfunc/_hwfoc         # with fpath+=(~/.zfunc) before compinit
  hwfoc completions fish > ~/.config/fish/completions/hwfoc.fish
  hwfoc completions powershell >> $PROFILE";

/// Options of `hwfoc completions`.
#[derive(Debug, Args)]
#[command(after_help = AFTER_HELP)]
pub struct CompletionsArgs {
    /// The shell to write the completion script for.
    #[arg(value_enum)]
    pub shell: Shell,
}

/// Runs `hwfoc completions`: writes the script for `command` (the whole command line) to
/// standard output.
pub fn run(args: &CompletionsArgs, mut command: clap::Command) -> Result<(), CliError> {
    let mut buf = script(args.shell, &mut command);
    let mut out = TextSink::create(None)?;
    out.write(&mut buf)?;
    out.flush()
}

/// The completion script of `command` for `shell`.
fn script(shell: Shell, command: &mut clap::Command) -> Vec<u8> {
    let name = command.get_name().to_string();
    let mut buf = Vec::new();
    clap_complete::generate(shell, command, name, &mut buf);
    buf
}

#[cfg(test)]
mod tests {
    use clap::{Arg, Command};

    use super::*;

    /// Each shell's script names the command and its subcommands and options.
    #[test]
    fn scripts_name_the_commands_and_options() {
        let mut command = Command::new("tool")
            .subcommand(Command::new("decode").arg(Arg::new("format").long("format")));
        for shell in [Shell::Bash, Shell::Zsh, Shell::Fish, Shell::PowerShell] {
            let text = String::from_utf8(script(shell, &mut command)).unwrap();
            assert!(text.contains("tool"), "{shell}: {text}");
            assert!(text.contains("decode"), "{shell}: {text}");
            assert!(text.contains("format"), "{shell}: {text}");
        }
    }
}
