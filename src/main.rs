fn main() {
    eprintln!("rod_ig_node: being written");
    std::process::exit(2);
}
