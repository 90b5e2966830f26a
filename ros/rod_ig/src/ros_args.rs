//! The ROS 2 command-line conventions, as rcl implements them (design articles "ROS 2 command
//! line arguments" and "Remapping Names"; rcl `arguments.c`, `remap.c`,
//! `expand_topic_name.c`): `--ros-args … [--]` blocks with `-r/--remap`, `-p/--param`,
//! `--params-file`, `--log-level`, `-e/--enclave` and the logging switches; the node's name
//! and namespace (`__node:=`, `__ns:=`); name expansion (relative, private `~`, `{node}`,
//! `{ns}` substitutions) and topic/service remapping, first matching rule wins.
//!
//! ros2-client parses none of this; the node resolves every name it creates through a
//! [`NodeIdentity`]. Pure: no I/O.

use std::path::PathBuf;

use thiserror::Error;

/// A command line that does not follow the conventions.
#[derive(Debug, Error, PartialEq, Eq)]
pub enum RosArgsError {
    /// A flag needs a value and the command line ends.
    #[error("{flag} needs {what}")]
    MissingValue {
        /// The flag.
        flag: String,
        /// What it needs.
        what: &'static str,
    },
    /// A rule or assignment without `:=`.
    #[error("{flag} {arg:?}: expected {form}")]
    Malformed {
        /// The flag.
        flag: String,
        /// Its argument.
        arg: String,
        /// The expected form.
        form: &'static str,
    },
    /// An argument the node does not know.
    #[error("unknown argument {0:?} (see --help)")]
    Unknown(String),
    /// An invalid node name, namespace or topic name.
    #[error("invalid {kind} {name:?}: {reason}")]
    InvalidName {
        /// Node name, namespace or topic name.
        kind: &'static str,
        /// The name.
        name: String,
        /// Why.
        reason: String,
    },
    /// An unknown log level.
    #[error("unknown log level {0:?} (debug, info, warn, error, fatal)")]
    LogLevel(String),
}

/// Severity levels of `--log-level` (rcutils), least severe first.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum LogLevel {
    /// DEBUG.
    Debug,
    /// INFO.
    Info,
    /// WARN.
    Warn,
    /// ERROR.
    Error,
    /// FATAL (reported as error by the console logger, which has no fatal level).
    Fatal,
}

impl LogLevel {
    fn parse(s: &str) -> Result<Self, RosArgsError> {
        Ok(match s.to_ascii_lowercase().as_str() {
            "debug" => Self::Debug,
            "info" => Self::Info,
            "warn" | "warning" => Self::Warn,
            "error" => Self::Error,
            "fatal" => Self::Fatal,
            _ => return Err(RosArgsError::LogLevel(s.to_string())),
        })
    }

    /// The `env_logger` / `log` level name.
    pub fn as_filter(self) -> &'static str {
        match self {
            Self::Debug => "debug",
            Self::Info => "info",
            Self::Warn => "warn",
            Self::Error | Self::Fatal => "error",
        }
    }
}

/// One `-r [node:]from:=to` rule.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Remap {
    /// The node the rule is for (`node:` prefix), or every node.
    pub node: Option<String>,
    /// Name matched (before expansion), or `__ns` / `__node`.
    pub from: String,
    /// Replacement (before expansion).
    pub to: String,
}

/// A parameter source, in command-line order (later ones override earlier ones).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ParamSource {
    /// `-p [node:]name:=value`, the value as YAML text.
    Value {
        /// The node the assignment is for, or every node.
        node: Option<String>,
        /// Parameter name.
        name: String,
        /// Its value, as written.
        value: String,
    },
    /// `--params-file FILE`.
    File(PathBuf),
}

/// The parsed command line.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct RosArgs {
    /// `-h` / `--help` outside a `--ros-args` block.
    pub help: bool,
    /// Remapping rules, in order.
    pub remaps: Vec<Remap>,
    /// Parameter assignments and files, in order.
    pub params: Vec<ParamSource>,
    /// `--log-level [logger:=]level`: `None` is the global level.
    pub log_levels: Vec<(Option<String>, LogLevel)>,
    /// `-e/--enclave` (recorded; DDS security is not used).
    pub enclave: Option<String>,
    /// `--enable-rosout-logs` / `--disable-rosout-logs` (last wins; default enabled).
    pub rosout_logs: Option<bool>,
    /// `--enable-stdout-logs` / `--disable-stdout-logs` (last wins; default enabled).
    pub stdout_logs: Option<bool>,
    /// Arguments outside `--ros-args` blocks that are not ROS flags.
    pub unparsed: Vec<String>,
}

/// Splits `[node:]rest` where rest holds `:=`: the node prefix is what precedes the first
/// single `:` that is not part of `:=` (rcl's lexer: names never contain `:`).
fn split_node_prefix(arg: &str) -> (Option<String>, &str) {
    let assign = arg.find(":=").unwrap_or(arg.len());
    match arg[..assign].find(':') {
        Some(i) => (Some(arg[..i].to_string()), &arg[i + 1..]),
        None => (None, arg),
    }
}

/// Parses a command line (without the program name). Outside `--ros-args` blocks the ROS
/// flags are accepted too (the node's command line has no other flags, and earlier releases
/// took `-p` and `--params-file` bare); anything else outside is [`RosArgs::unparsed`], and
/// anything unknown inside a block is an error.
pub fn parse<I, S>(args: I) -> Result<RosArgs, RosArgsError>
where
    I: IntoIterator<Item = S>,
    S: AsRef<str>,
{
    let mut out = RosArgs::default();
    let mut in_block = false;
    let mut it = args.into_iter().map(|s| s.as_ref().to_string());
    while let Some(arg) = it.next() {
        let mut value = |what: &'static str| {
            it.next().ok_or_else(|| RosArgsError::MissingValue {
                flag: arg.clone(),
                what,
            })
        };
        match arg.as_str() {
            "--ros-args" => in_block = true,
            "--" => in_block = false,
            "-h" | "--help" if !in_block => out.help = true,
            "-r" | "--remap" => {
                let rule = value("a rule FROM:=TO")?;
                let (node, rest) = split_node_prefix(&rule);
                let (from, to) = rest.split_once(":=").ok_or(RosArgsError::Malformed {
                    flag: arg.clone(),
                    arg: rule.clone(),
                    form: "[NODE:]FROM:=TO",
                })?;
                let remap = Remap {
                    node,
                    from: from.trim().to_string(),
                    to: to.trim().to_string(),
                };
                check_rule(&remap)?;
                out.remaps.push(remap);
            }
            "-p" | "--param" => {
                let kv = value("NAME:=VALUE")?;
                let (node, rest) = split_node_prefix(&kv);
                let (name, v) = rest.split_once(":=").ok_or(RosArgsError::Malformed {
                    flag: arg.clone(),
                    arg: kv.clone(),
                    form: "[NODE:]NAME:=VALUE",
                })?;
                out.params.push(ParamSource::Value {
                    node,
                    name: name.trim().to_string(),
                    value: v.to_string(),
                });
            }
            "--params-file" => {
                let f = value("a FILE")?;
                out.params.push(ParamSource::File(PathBuf::from(f)));
            }
            "--log-level" => {
                let l = value("a LEVEL or LOGGER:=LEVEL")?;
                match l.split_once(":=") {
                    Some((logger, level)) => out
                        .log_levels
                        .push((Some(logger.to_string()), LogLevel::parse(level)?)),
                    None => out.log_levels.push((None, LogLevel::parse(&l)?)),
                }
            }
            "-e" | "--enclave" => out.enclave = Some(value("an ENCLAVE")?),
            "--log-file-name" | "--log-config-file" => {
                value("a NAME")?;
            }
            "--enable-rosout-logs" => out.rosout_logs = Some(true),
            "--disable-rosout-logs" => out.rosout_logs = Some(false),
            "--enable-stdout-logs" => out.stdout_logs = Some(true),
            "--disable-stdout-logs" => out.stdout_logs = Some(false),
            "--enable-external-lib-logs" | "--disable-external-lib-logs" => {}
            _ if in_block => return Err(RosArgsError::Unknown(arg)),
            _ if arg.starts_with('-') => return Err(RosArgsError::Unknown(arg)),
            _ => out.unparsed.push(arg),
        }
    }
    Ok(out)
}

/// Validates the special rules at parse time (so that a bad `__ns` fails before the node
/// starts, with the argument named).
fn check_rule(r: &Remap) -> Result<(), RosArgsError> {
    match r.from.as_str() {
        "__ns" => validate_namespace(&r.to),
        "__node" | "__name" => validate_node_name(&r.to),
        _ => Ok(()),
    }
}

/// rmw's node-name rule: `[A-Za-z_][A-Za-z0-9_]*`, at most 255 characters.
pub fn validate_node_name(name: &str) -> Result<(), RosArgsError> {
    let bad = |reason: &str| RosArgsError::InvalidName {
        kind: "node name",
        name: name.to_string(),
        reason: reason.to_string(),
    };
    if name.is_empty() {
        return Err(bad("empty"));
    }
    if name.len() > 255 {
        return Err(bad("longer than 255 characters"));
    }
    if name.starts_with(|c: char| c.is_ascii_digit()) {
        return Err(bad("starts with a digit"));
    }
    if !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
        return Err(bad("only letters, digits and '_' are allowed"));
    }
    Ok(())
}

/// rmw's namespace rule: absolute, tokens `[A-Za-z_][A-Za-z0-9_]*` separated by single `/`,
/// no trailing `/` except the root `/`.
pub fn validate_namespace(ns: &str) -> Result<(), RosArgsError> {
    validate_absolute(ns, "namespace", false)
}

/// A fully qualified topic or service name (after expansion): as a namespace, and not `/`.
pub fn validate_topic_name(name: &str) -> Result<(), RosArgsError> {
    validate_absolute(name, "topic name", true)
}

fn validate_absolute(name: &str, kind: &'static str, topic: bool) -> Result<(), RosArgsError> {
    let bad = |reason: &str| RosArgsError::InvalidName {
        kind,
        name: name.to_string(),
        reason: reason.to_string(),
    };
    if !name.starts_with('/') {
        return Err(bad("must be absolute (start with '/')"));
    }
    if name == "/" {
        return if topic {
            Err(bad("is the root"))
        } else {
            Ok(())
        };
    }
    if name.ends_with('/') {
        return Err(bad("ends with '/'"));
    }
    for token in name[1..].split('/') {
        if token.is_empty() {
            return Err(bad("contains '//'"));
        }
        if token.starts_with(|c: char| c.is_ascii_digit()) {
            return Err(bad("a token starts with a digit"));
        }
        if !token.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
            return Err(bad("only letters, digits, '_' and '/' are allowed"));
        }
    }
    Ok(())
}

/// The node's effective name and namespace and its topic/service remapping rules.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct NodeIdentity {
    /// Node name (after `__node:=`).
    pub name: String,
    /// Absolute namespace (after `__ns:=`), `/` for the root.
    pub namespace: String,
    /// Name rules that apply to this node, in order.
    rules: Vec<(String, String)>,
}

/// The Rust log target of the node's own modules (its library crate, `rod_ig_node::...`).
pub const NODE_LOG_TARGET: &str = "rod_ig_node";

impl RosArgs {
    /// The node's identity: `default_name` in `default_namespace`, renamed by the last
    /// `__node`/`__name` and moved by the last `__ns` rule that applies to it (a rule with a
    /// node prefix applies when the prefix is the node's default name, as in rcl).
    pub fn identity(
        &self,
        default_name: &str,
        default_namespace: &str,
    ) -> Result<NodeIdentity, RosArgsError> {
        let applies = |r: &Remap| r.node.as_deref().is_none_or(|n| n == default_name);
        let mut name = default_name.to_string();
        let mut namespace = default_namespace.to_string();
        let mut rules = Vec::new();
        for r in self.remaps.iter().filter(|r| applies(r)) {
            match r.from.as_str() {
                "__node" | "__name" => name = r.to.clone(),
                "__ns" => namespace = r.to.clone(),
                _ => rules.push((r.from.clone(), r.to.clone())),
            }
        }
        validate_node_name(&name)?;
        validate_namespace(&namespace)?;
        Ok(NodeIdentity {
            name,
            namespace,
            rules,
        })
    }

    /// The threshold of the ROS logger `logger` (`left.rod_ig_node`): the last `--log-level`
    /// that names it or no logger at all, else INFO (rcutils' default), as rcl applies it to
    /// the console and /rosout alike.
    pub fn level_of(&self, logger: &str) -> LogLevel {
        self.log_levels
            .iter()
            .rev()
            .find(|(l, _)| l.as_deref().is_none_or(|l| l == logger))
            .map_or(LogLevel::Info, |(_, level)| *level)
    }

    /// An `env_logger` filter from the `--log-level` settings (global first, then per logger;
    /// ROS logger names use `.` where Rust modules use `::`), or `None` when there are none.
    /// The node's own ROS logger (`own_logger`, e.g. `left.rod_ig_node` for a namespaced or
    /// renamed node) sets the level of the node's Rust modules ([`NODE_LOG_TARGET`]) on the
    /// console too, as it does on /rosout.
    pub fn log_filter(&self, own_logger: &str) -> Option<String> {
        if self.log_levels.is_empty() {
            return None;
        }
        let parts: Vec<String> = self
            .log_levels
            .iter()
            .map(|(logger, level)| match logger {
                None => level.as_filter().to_string(),
                Some(l) if l == own_logger => {
                    format!("{NODE_LOG_TARGET}={}", level.as_filter())
                }
                Some(l) => format!("{}={}", l.replace('.', "::"), level.as_filter()),
            })
            .collect();
        Some(parts.join(","))
    }
}

impl NodeIdentity {
    /// The node's ROS logger name, as rclcpp names it: the namespace and the name joined by
    /// dots (`/left` + `rod_ig_node` → `left.rod_ig_node`; `rod_ig_node` in `/`).
    pub fn logger_name(&self) -> String {
        self.namespace
            .split('/')
            .filter(|t| !t.is_empty())
            .chain([self.name.as_str()])
            .collect::<Vec<_>>()
            .join(".")
    }

    /// `namespace/name`.
    pub fn fully_qualified_name(&self) -> String {
        join(&self.namespace, &self.name)
    }

    /// rcl_expand_topic_name: `{node}`, `{ns}`/`{namespace}` substituted; `~` is the node's
    /// private namespace; a relative name is put in the node's namespace. The result is
    /// validated.
    pub fn expand(&self, name: &str) -> Result<String, RosArgsError> {
        if name.is_empty() {
            return Err(RosArgsError::InvalidName {
                kind: "topic name",
                name: name.into(),
                reason: "empty".into(),
            });
        }
        if name.contains("//") {
            return Err(RosArgsError::InvalidName {
                kind: "topic name",
                name: name.into(),
                reason: "contains '//'".into(),
            });
        }
        let mut s = name
            .replace("{node}", &self.name)
            .replace("{namespace}", &self.namespace)
            .replace("{ns}", &self.namespace);
        if s == "~" {
            s = self.fully_qualified_name();
        } else if let Some(rest) = s.strip_prefix("~/") {
            s = join(&self.fully_qualified_name(), rest);
        } else if !s.starts_with('/') {
            s = join(&self.namespace, &s);
        }
        // Substituted namespaces may leave "//" at the seam.
        while s.contains("//") {
            s = s.replace("//", "/");
        }
        validate_topic_name(&s)?;
        Ok(s)
    }

    /// The name a topic or service `name` gets: expanded, then the first remapping rule whose
    /// expanded `from` equals it gives the (expanded) replacement.
    pub fn resolve(&self, name: &str) -> Result<String, RosArgsError> {
        let expanded = self.expand(name)?;
        for (from, to) in &self.rules {
            if self.expand(from).is_ok_and(|f| f == expanded) {
                return self.expand(to);
            }
        }
        Ok(expanded)
    }

    /// [`Self::resolve`] split into (namespace, base name), as ros2-client's `Name` takes it.
    pub fn resolve_split(&self, name: &str) -> Result<(String, String), RosArgsError> {
        let full = self.resolve(name)?;
        let i = full.rfind('/').unwrap_or(0);
        let ns = if i == 0 { "/" } else { &full[..i] };
        Ok((ns.to_string(), full[i + 1..].to_string()))
    }
}

fn join(ns: &str, rest: &str) -> String {
    if ns == "/" {
        format!("/{rest}")
    } else {
        format!("{ns}/{rest}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args(s: &str) -> Result<RosArgs, RosArgsError> {
        parse(s.split_whitespace())
    }

    fn id(s: &str) -> NodeIdentity {
        args(s).unwrap().identity("rod_ig_node", "/").unwrap()
    }

    #[test]
    fn plain_start_keeps_the_defaults() {
        let n = id("");
        assert_eq!(n.fully_qualified_name(), "/rod_ig_node");
        assert_eq!(n.resolve("rod/target").unwrap(), "/rod/target");
        assert_eq!(n.resolve("/rod/target").unwrap(), "/rod/target");
    }

    #[test]
    fn namespace_moves_relative_names_only() {
        let n = id("--ros-args -r __ns:=/left");
        assert_eq!(n.fully_qualified_name(), "/left/rod_ig_node");
        assert_eq!(n.resolve("rod/target").unwrap(), "/left/rod/target");
        assert_eq!(n.resolve("/clock").unwrap(), "/clock");
        assert_eq!(n.resolve("~/status").unwrap(), "/left/rod_ig_node/status");
        assert_eq!(n.resolve("~").unwrap(), "/left/rod_ig_node");
        let n = id("--ros-args -r __ns:=/cell/left");
        assert_eq!(n.resolve("rod/solve").unwrap(), "/cell/left/rod/solve");
    }

    #[test]
    fn node_rename_and_private_names() {
        let n = id("--ros-args -r __node:=arm_rod -r __ns:=/a");
        assert_eq!(n.fully_qualified_name(), "/a/arm_rod");
        assert_eq!(n.resolve("~/x").unwrap(), "/a/arm_rod/x");
        assert_eq!(n.resolve("{node}/x").unwrap(), "/a/arm_rod/x");
        assert_eq!(n.resolve("/{ns}/y").unwrap(), "/a/y");
        assert_eq!(id("--ros-args -r __name:=b").name, "b");
    }

    #[test]
    fn topic_remaps_match_expanded_names_first_rule_wins() {
        let n = id("--ros-args -r /rod/target:=/arm/goal -r rod/target:=/other");
        assert_eq!(n.resolve("rod/target").unwrap(), "/arm/goal");
        // Relative rules are expanded in the node's namespace, on both sides.
        let n = id("--ros-args -r __ns:=/left -r rod/target:=goal");
        assert_eq!(n.resolve("rod/target").unwrap(), "/left/goal");
        assert_eq!(n.resolve("rod/path").unwrap(), "/left/rod/path");
        // A rule for the absolute name does not match the namespaced one.
        let n = id("--ros-args -r __ns:=/left -r /rod/target:=/x");
        assert_eq!(n.resolve("rod/target").unwrap(), "/left/rod/target");
    }

    #[test]
    fn node_prefixed_rules_apply_to_that_node_only() {
        let a = args("--ros-args -r other:__ns:=/x -r rod_ig_node:rod/path:=/p").unwrap();
        let n = a.identity("rod_ig_node", "/").unwrap();
        assert_eq!(n.namespace, "/");
        assert_eq!(n.resolve("rod/path").unwrap(), "/p");
        let o = a.identity("other", "/").unwrap();
        assert_eq!(o.namespace, "/x");
        assert_eq!(o.resolve("rod/path").unwrap(), "/x/rod/path");
    }

    #[test]
    fn parameters_files_and_log_levels_in_order() {
        let a = args(
            "--ros-args -p a:=1 --params-file f.yaml --param rod_ig_node:b:=x:=y \
             --log-level debug --log-level rustdds:=ERROR -- user_arg",
        )
        .unwrap();
        assert_eq!(
            a.params,
            vec![
                ParamSource::Value {
                    node: None,
                    name: "a".into(),
                    value: "1".into()
                },
                ParamSource::File("f.yaml".into()),
                ParamSource::Value {
                    node: Some("rod_ig_node".into()),
                    name: "b".into(),
                    value: "x:=y".into()
                },
            ]
        );
        assert_eq!(a.log_filter("rod_ig_node").unwrap(), "debug,rustdds=error");
        assert_eq!(a.unparsed, vec!["user_arg".to_string()]);
        let a = args("--ros-args --log-level ros2_client.node:=warn").unwrap();
        assert_eq!(
            a.log_filter("rod_ig_node").unwrap(),
            "ros2_client::node=warn"
        );
        // A namespaced, renamed node: its own logger sets the console level of its modules.
        let a =
            args("--ros-args -r __ns:=/left -r __node:=arm --log-level left.arm:=debug").unwrap();
        let own = a.identity("rod_ig_node", "/").unwrap().logger_name();
        assert_eq!(own, "left.arm");
        assert_eq!(a.log_filter(&own).unwrap(), "rod_ig_node=debug");
    }

    #[test]
    fn switches_and_help() {
        let a = args("-h --ros-args --disable-rosout-logs -e /enc --enable-stdout-logs").unwrap();
        assert!(a.help);
        assert_eq!(a.rosout_logs, Some(false));
        assert_eq!(a.stdout_logs, Some(true));
        assert_eq!(a.enclave.as_deref(), Some("/enc"));
        // Bare flags without --ros-args are accepted (earlier releases' command line).
        let a = args("-p rod_length:=2").unwrap();
        assert_eq!(a.params.len(), 1);
    }

    #[test]
    fn bad_command_lines_say_what_is_wrong() {
        for (line, needle) in [
            ("--ros-args -r", "needs"),
            ("--ros-args -r foo", "FROM:=TO"),
            ("--ros-args -p x", "NAME:=VALUE"),
            ("--ros-args --frobnicate", "unknown argument"),
            ("--frobnicate", "unknown argument"),
            ("--ros-args -r __ns:=left", "absolute"),
            ("--ros-args -r __ns:=/a//b", "//"),
            ("--ros-args -r __ns:=/a/", "ends with"),
            ("--ros-args -r __node:=9lives", "digit"),
            ("--ros-args -r __node:=a-b", "letters"),
            ("--ros-args --log-level loud", "log level"),
            ("--ros-args --params-file", "FILE"),
        ] {
            let e = args(line).unwrap_err().to_string();
            assert!(e.contains(needle), "{line}: {e}");
        }
        let n = id("");
        for bad in ["", "a b", "/a/", "1x", "a//b", "/"] {
            assert!(n.resolve(bad).is_err(), "{bad:?}");
        }
    }

    #[test]
    fn resolve_split_gives_namespace_and_base() {
        let n = id("--ros-args -r __ns:=/left");
        assert_eq!(
            n.resolve_split("rod/target").unwrap(),
            ("/left/rod".to_string(), "target".to_string())
        );
        assert_eq!(
            id("").resolve_split("/clock").unwrap(),
            ("/".to_string(), "clock".to_string())
        );
    }

    #[test]
    fn logger_names_and_thresholds_as_rcl() {
        let a = args("--ros-args -r __ns:=/left/arm --log-level warn --log-level left.arm.rod_ig_node:=debug")
            .unwrap();
        let id = a.identity("rod_ig_node", "/").unwrap();
        assert_eq!(id.logger_name(), "left.arm.rod_ig_node");
        assert_eq!(a.level_of(&id.logger_name()), LogLevel::Debug);
        assert_eq!(a.level_of("other"), LogLevel::Warn);
        let root = args("").unwrap().identity("rod_ig_node", "/").unwrap();
        assert_eq!(root.logger_name(), "rod_ig_node");
        assert_eq!(args("").unwrap().level_of("rod_ig_node"), LogLevel::Info);
        assert!(LogLevel::Debug < LogLevel::Info && LogLevel::Error < LogLevel::Fatal);
    }
}
