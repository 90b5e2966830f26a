//! `rod_ig_echo`: the latency benchmark's baseline. Same middleware set-up, topics and QoS
//! as `rod_ig_node`, but no solving: each `/rod/target` is answered at once on `/rod/path`
//! with a Path of `path_samples` copies of the target (same message size as the node's).
//!
//! Usage: `rod_ig_echo [path_samples]` (default 100). Honours ROS_DOMAIN_ID and
//! ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST like the node.

use std::pin::pin;

use futures::StreamExt;
use rod_ig_node::messages::{type_names, Path, PoseStamped};
use rod_ig_node::node::{topic_qos, MiddlewareConfig};
use ros2_client::dds::rustdds::DomainParticipantBuilder;
use ros2_client::{Context, Name, NodeName, NodeOptions};

fn main() {
    env_logger::Builder::from_env(
        env_logger::Env::default().default_filter_or("warn,rustdds=error"),
    )
    .init();
    let samples: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(100);
    let mw = MiddlewareConfig::from_env().unwrap_or_else(|e| {
        eprintln!("rod_ig_echo: {e}");
        std::process::exit(2)
    });
    let rt = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .expect("tokio runtime");
    rt.block_on(async move {
        let mut b = DomainParticipantBuilder::new(mw.domain_id);
        if mw.localhost_only {
            b = b.with_only_networks([std::net::Ipv4Addr::LOCALHOST]);
        }
        let ctx =
            Context::from_domain_participant(b.build().expect("participant")).expect("context");
        let mut node = ctx
            .new_node(
                NodeName::new("/", "rod_ig_echo").expect("name"),
                NodeOptions::new(),
            )
            .expect("node");
        let qos = topic_qos();
        let t_in = node
            .create_topic(
                &Name::new("/rod", "target").expect("name"),
                type_names::pose_stamped(),
                &qos,
            )
            .expect("topic");
        let t_out = node
            .create_topic(
                &Name::new("/rod", "path").expect("name"),
                type_names::path(),
                &qos,
            )
            .expect("topic");
        let sub = node
            .create_subscription::<PoseStamped>(&t_in, Some(qos.clone()))
            .expect("sub");
        let publisher = node
            .create_publisher::<Path>(&t_out, Some(qos.clone()))
            .expect("pub");
        let spinner = node.spinner().expect("spinner");
        tokio::spawn(spinner.spin());
        eprintln!("rod_ig_echo ready: domain {}", mw.domain_id);
        let echo = async {
            let mut stream = pin!(sub.async_stream());
            while let Some(Ok((t, _))) = stream.next().await {
                let path = Path {
                    header: t.header.clone(),
                    poses: vec![t; samples],
                };
                let _ = publisher.publish(path);
            }
        };
        tokio::select! {
            _ = echo => {},
            _ = tokio::signal::ctrl_c() => {},
        }
    });
}
