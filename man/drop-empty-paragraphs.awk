# scdoc opens a paragraph (.P) after every heading, before every heading or paragraph and before the end of
# every indented block, where roff has nothing to open; mandoc -T lint warns about each. This keeps a .P only
# where text follows it.
function flush_pending(next_line) {
    if (pending && next_line !~ /^\.(SH|SS|P|RE)( |$)/)
        print ".P"
    pending = 0
}
/^\.P$/ {
    if (previous !~ /^\.(TH|SH|SS|P)( |$)/)
        pending = 1
    previous = $0
    next
}
{
    flush_pending($0)
    print
    previous = $0
}
