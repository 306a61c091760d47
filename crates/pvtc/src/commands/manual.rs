//! `pvtc completions SHELL` and `pvtc man`: the shell completions and the manual page,
//! generated from the argument definitions (clap_complete, clap_mangen), so they list
//! exactly the options `--help` does.
//!
//! Owns the layout of the manual page. It must not describe an option by itself.

use crate::args::Cli;
use crate::output;
use crate::report::Reporter;
use std::process::ExitCode;

/// `pvtc completions SHELL`: the completion script on standard output.
pub fn completions(shell: clap_complete::Shell) -> ExitCode {
    let mut command = <Cli as clap::CommandFactory>::command();
    let mut script = Vec::new();
    clap_complete::generate(shell, &mut command, "pvtc", &mut script);
    output::write_stdout_status(&script, &Reporter::human())
}

/// The manual page of pvtc (roff), one page: name, synopsis, description, options, the
/// list of subcommands (each pointing to its section below, as there are no
/// `pvtc-compile(1)` pages), version, then for each subcommand (`pvtc compile`, …) its
/// synopsis and options.
pub fn man_page_text() -> Vec<u8> {
    let command = <Cli as clap::CommandFactory>::command();
    let mut page = Vec::new();
    // Rendering into memory cannot fail: the results are io::Results of a Vec's writes.
    let man = clap_mangen::Man::new(command.clone());
    let _ = man.render_title(&mut page);
    let _ = man.render_name_section(&mut page);
    let _ = man.render_synopsis_section(&mut page);
    let _ = man.render_description_section(&mut page);
    let _ = man.render_options_section(&mut page);
    page.extend_from_slice(b".SH SUBCOMMANDS\n");
    for sub in command.get_subcommands() {
        let name = format!("pvtc {}", sub.get_name());
        let about = sub.get_about().map(|a| a.to_string()).unwrap_or_default();
        let item = format!(
            ".TP\n\\fB{}\\fR\n{} (see {} below)\n",
            name,
            roff_text(&about),
            name.to_uppercase()
        );
        page.extend_from_slice(item.as_bytes());
    }
    let _ = man.render_version_section(&mut page);
    for sub in command.get_subcommands() {
        let name = format!("pvtc {}", sub.get_name());
        let about = sub.get_about().map(|a| a.to_string()).unwrap_or_default();
        let heading = format!(".SH \"{}\"\n{}\n", name.to_uppercase(), roff_text(&about));
        page.extend_from_slice(heading.as_bytes());
        let man = clap_mangen::Man::new(sub.clone().bin_name(name));
        let _ = man.render_synopsis_section(&mut page);
        let _ = man.render_options_section(&mut page);
    }
    page
}

/// Plain text as a roff text line: a leading `.` or `'` would read as a request.
fn roff_text(text: &str) -> String {
    let text = text.replace('\\', "\\e");
    if text.starts_with(['.', '\'']) {
        format!("\\&{text}")
    } else {
        text
    }
}

/// `pvtc man`: the manual page on standard output.
pub fn man_page() -> ExitCode {
    output::write_stdout_status(&man_page_text(), &Reporter::human())
}
