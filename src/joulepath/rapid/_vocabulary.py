"""The interpreter's own vocabulary: which instruction names move the arm (and how), which set or
wait on signals, which write what the program learns at run time, which instructions and functions it
knows without running them. The documented signatures of RAPID's instructions and functions are
:mod:`joulepath.rapid.builtins`'s table."""

from __future__ import annotations

from joulepath.rapid.values import Value

RAPID_AXES = 6
JOINT_MOTIONS = {"movej": "MoveJ", "movejdo": "MoveJ", "movejsync": "MoveJ", "triggj": "MoveJ"}
LINEAR_MOTIONS = {
    "movel": "MoveL",
    "moveldo": "MoveL",
    "movelsync": "MoveL",
    "triggl": "MoveL",
    "triggliosens": "MoveL",
}
CIRCULAR_MOTIONS = {"movec": "MoveC", "movecdo": "MoveC", "movecsync": "MoveC", "triggc": "MoveC"}
ABSJ_MOTIONS = {"moveabsj": "MoveAbsJ", "moveabsjsync": "MoveAbsJ", "triggabsj": "MoveAbsJ"}
PROCESS_LINEAR = {
    "arcl", "arclstart", "arclend", "arcl1", "arcl2", "paintl", "displ", "capl", "caplstart", "caplend",
    "laserl", "cutl", "gluel", "dispensel", "egmmovel",
}  # fmt: skip
PROCESS_CIRCULAR = {
    "arcc", "arccstart", "arccend", "arcc1", "arcc2", "paintc", "dispc", "capc", "gluec", "egmmovec",
}  # fmt: skip
EGM_MOTIONS = {"egmmovel", "egmmovec"}
"""Moves whose path an external sensor corrects through EGM while they run (``EGMMoveL``, ``EGMMoveC``)."""
SEARCH_MOTIONS = {"searchl": "MoveL", "searchc": "MoveC", "searchj": "MoveJ", "searchextj": "MoveJ"}

IO_SETTERS = {"setdo", "set", "reset", "pulsedo", "invertdo", "setgo", "setao", "setdosync"}
IO_WAITS = {"waitdi", "waitdo", "waitgi", "waitgo", "waitai", "waitao"}
INPUT_WRITERS = {
    "tpreadnum": (0,),
    "tpreaddnum": (0,),
    "tpreadfk": (0,),
    "uiNumEntry".lower(): (),
    "socketreceive": (),
    "socketreceivefrom": (),
    "readanybin": (1,),
    "readrawbytes": (1,),
    "rmqreadwait": (0,),
    "rmqgetmsgdata": (1,),
    "camgetresult": (1,),
    "searchl": (1,),
    "searchc": (1,),
    "getdataval": (1,),
    "strtoval": (),
    "waitsynctask": (),
}
"""Instructions that write what the program learns at run time: the positional arguments (0-based)
they write; every variable passed as an optional argument (``\\Str:=s``) is written too."""
KNOWN_INSTRUCTIONS = {
    # motion settings and motion control
    "accset", "velset", "gripload", "confj", "confl", "singarea", "pathacclim", "worldacclim",
    "pdispon", "pdispset", "pdispoff", "eoffson", "eoffsset", "eoffsoff", "circpathmode", "motionsup",
    "stopmove", "startmove", "startmovelretry", "stopmovereset", "storepath", "restopath", "clearpath",
    "tuneservo", "tunereset", "softact", "softdeact", "actunit", "deactunit", "mechunitload",
    "syncmoveon", "syncmoveoff", "syncmoveundo", "waitrob", "speedrefresh", "movecsync", "moveextj",
    "indamove", "indcmove", "inddmove", "indrmove", "indreset", "corrcon", "corrdiscon", "corrwrite",
    "corrclear", "triggio", "triggeq", "triggequip", "triggint", "triggspeed", "triggcheckio",
    "triggrampaio", "triggdataset", "triggstopproc", "triggdatareset", "pathrecstart", "pathrecstop",
    "pathrecmovebwd", "pathrecmovefwd", "pathresol", "setsysdata", "getsysdata", "loadid",
    "egmactjoint", "egmactpose", "egmrunjoint", "egmrunpose", "egmstop", "egmreset", "egmsetupuc",
    "egmgetid", "egmstreamstart", "egmstreamstop",
    # waits and flow
    "waittime", "waituntil", "waitdi", "waitdo", "waitgi", "waitgo", "waitai", "waitao", "waitsynctask",
    "waitload", "waittestandset", "waitwobj", "dropwobj", "stop", "break", "exitcycle", "systemstopaction",
    "callbyvar", "load", "unload", "startload", "erasemodule", "done",
    # data
    "incr", "decr", "add", "clear", "copyrawbytes", "clearrawbytes", "packrawbytes", "unpackrawbytes",
    "setdataval", "getdataval", "setalldataval", "bitset", "bitclear", "strtoval", "packdnheader",
    # I/O
    "setdo", "set", "reset", "pulsedo", "invertdo", "setgo", "setao", "setdosync", "ioenable",
    "iodisable", "aliasio", "aliasioreset",
    # interrupts and errors
    "connect", "isignaldi", "isignaldo", "isignalgi", "isignalgo", "isignalai", "isignalao", "itimer",
    "idelete", "ienable", "idisable", "isleep", "iwatch", "ipers", "ierror", "ivarval", "raisetouser",
    "errwrite", "errlog", "errraise", "skipwarn", "reseterr", "resetretrycount",
    # operator and text
    "tpwrite", "tperase", "tpreadnum", "tpreaddnum", "tpreadfk", "tpshow", "uimsgbox", "uishow",
    "uinumentry", "uinumtune", "uialphaentry", "uilistview",
    # clocks, files, sockets, messages
    "clkreset", "clkstart", "clkstop", "open", "close", "write", "writebin", "writestrbin",
    "writeanybin", "writerawbytes", "readanybin", "readrawbytes", "rewind", "makedir", "removedir",
    "removefile", "renamefile", "copyfile", "closedir", "opendir", "socketcreate", "socketconnect",
    "socketsend", "socketsendto", "socketreceive", "socketreceivefrom", "socketclose", "socketbind",
    "socketlisten", "socketaccept", "rmqsendmessage", "rmqreadwait", "rmqgetmessage", "rmqgetmsgdata",
    "rmqgetmsgheader", "rmqfindslot", "rmqemptyqueue", "sendsoftid",
    # vision (Integrated Vision), welding and other process setup
    "camreqimage", "camgetresult", "camsetprogrammode", "camsetrunningmode", "camloadjob",
    "camsetexposure", "camsetparameter", "camstartloadjob", "camwaitloadjob", "camflush",
    "arcrefresh", "arckill", "setgripload",
}  # fmt: skip
KNOWN_FUNCTIONS_UNKNOWN_RESULT = {
    "clkread": 0.0, "cdate": "", "ctime": "", "gettime": 0.0, "readnum": 0.0, "readstr": "",
    "readbin": 0.0, "readstrbin": "", "opmode": "", "runmode": "", "isfile": False, "filesize": 0.0,
    "robos": True, "getnextsym": False, "getsysinfo": "", "getservicedata": 0.0, "numtoboolsafe": False,
    "testandset": True, "socketgetstatus": 0.0, "getmecunitname": "", "isstopstateevent": False,
    "rmqgetslotname": "", "uinumentry": 0.0, "uinumtune": 0.0, "uialphaentry": "", "uilistview": 1.0,
    "uimessagebox": 1.0, "tpreadfk": 0.0, "getmotorTorque".lower(): 0.0, "gettaskname": "T_ROB1",
    "isstopmoveact": False, "ismechunitactive": True, "getnextmechunit": False, "distance": 0.0,
    "camnumberofresults": 1.0, "camgetexposure": 0.0, "camgetloadedjob": "", "camgetname": "",
    "ispers": True, "isvar": True, "type": "", "argname": "", "getjointdata": 0.0,
    "testsignread": 0.0, "eventtype": 0.0, "execlevel": 0.0, "remainingretries": 0.0,
}  # fmt: skip
"""Built-in functions whose result is known only while the program runs, with their stand-in."""


ALL_MOTIONS = (
    set(JOINT_MOTIONS)
    | set(LINEAR_MOTIONS)
    | set(CIRCULAR_MOTIONS)
    | set(ABSJ_MOTIONS)
    | PROCESS_LINEAR
    | PROCESS_CIRCULAR
    | set(SEARCH_MOTIONS)
)
STANDIN_RESULT: dict[str, Value] = {
    k: ""
    for k in (
        "strpart",
        "numtostr",
        "dnumtostr",
        "valtostr",
        "booltostr",
        "bytetostr",
        "strmap",
        "stroneupper",
    )
} | {"strmemb": False, "strorder": False}
SIGNAL_FUNCS = {"dinput", "doutput", "ginput", "goutput", "ainput", "aoutput", "testdi", "validio"}
