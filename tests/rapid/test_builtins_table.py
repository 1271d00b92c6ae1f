# ruff: noqa: E501  (a call is one line, as a program writes it)
"""The table of RAPID's instructions, functions and data types (joulepath.rapid.builtins).

Calls are written here as a RAPID program writes them (usage in the manuals' style, typed anew
with our own names), split into ``(name, value)`` pairs by a small splitter of this file, and
matched against the table's signatures.
"""

import re

import pytest

from joulepath.rapid import builtins as bi
from joulepath.rapid.builtins import (
    ArgumentError,
    Effect,
    Kind,
    MotionKind,
    ParamKind,
    data_type,
    lookup,
    match_arguments,
    parse_signature,
)


# ---------------------------------------------------------------- a call's text -> (name, value) pairs
def _split_top(text: str, sep: str) -> list[str]:
    """``text`` split at ``sep`` outside brackets, parentheses and strings."""
    out, depth, cur, in_str = [], 0, "", False
    for c in text:
        if in_str:
            cur += c
            in_str = c != '"'
            continue
        if c == '"':
            in_str = True
        elif c in "([{":
            depth += 1
        elif c in ")]}":
            depth -= 1
        elif c == sep and depth == 0:
            out.append(cur)
            cur = ""
            continue
        cur += c
    out.append(cur)
    return out


def call_args(text: str) -> list[tuple[str | None, str | None]]:
    """The arguments of ``Name a, b \\Opt:=c, \\Sw;`` (text after the name), as the interpreter
    will give them: positional ``(None, text)``, named or optional ``(name, text)``, switch
    ``(name, None)``."""
    text = text.strip().rstrip(";").strip()
    if text.startswith("(") and text.endswith(")"):
        text = text[1:-1]
    out: list[tuple[str | None, str | None]] = []
    if not text:
        return out
    for piece in _split_top(text, ","):
        parts = _split_top(piece, "\\")
        head, opts = parts[0].strip(), parts[1:]
        if head:
            m = re.fullmatch(r"([A-Za-z_]\w*)\s*:=\s*(.+)", head, re.S)
            out.append((m.group(1), m.group(2).strip()) if m else (None, head))
        for o in opts:
            name, _, value = o.partition(":=")
            out.append((name.strip(), value.strip() or None))
    return out


def test_call_args_splits_as_rapid_reads():
    assert call_args(r"p10, v500\V:=550, z10\Z:=12, tool1\WObj:=wobj1;") == [
        (None, "p10"),
        (None, "v500"),
        ("V", "550"),
        (None, "z10"),
        ("Z", "12"),
        (None, "tool1"),
        ("WObj", "wobj1"),
    ]
    assert call_args(r"\Conc, Offs(p1, 0, 0, 10), v100, fine, tool0")[0] == ("Conc", None)
    assert call_args(r'"a, b" \Num:=reg1')[0] == (None, '"a, b"')


# ---------------------------------------------------------------- calls as programs write them
CALLS = r"""
MoveL p10, v1000, z50, tGripper;
MoveL \Conc, p10, v1000, z50, tGripper \WObj:=wobjTable;
MoveL p10, v1000\V:=1200, z40\Z:=45, tGripper;
MoveL p10, v1000\T:=4, fine\Inpos:=inpos50, tGripper\WObj:=wobj1\Corr;
MoveL Offs(p10, 0, 0, 100), v500, z10, tool0\WObj:=wobj0\TLoad:=load1;
MoveL ToPoint:=p10, Speed:=v500, Zone:=z10, Tool:=tool0;
MoveL p10\ID:=10, v500, z10, tool0;
MoveJ p20, vmax, z100, tGripper;
MoveJ \Conc, *, v2000\V:=2200, z40\Z:=45, tool1\WObj:=wobj2;
MoveC p30, p40, v500, z30, tool2;
MoveC \Conc, cir1, p15, v500\T:=5, fine, tool1\WObj:=wobj1\Corr;
MoveAbsJ jHome\NoEOffs, v1000, fine, tool0;
MoveAbsJ \Conc, jpos20, v1000\T:=3, z20\Z:=25, tGripper\WObj:=wobj1;
MoveExtJ jTrack, vrot20, z0;
MoveExtJ \Conc, jTrack\UseEOffs, vrot20\T:=5, fine\Inpos:=inpos20;
MoveLDO p1, v1000, fine, tool1, doGrip, 1;
MoveLDO p1, v1000\T:=2, z10, tool1\WObj:=wobj1, doGrip, 0;
MoveJDO p1, vmax, z30, tool2, do1, 1;
MoveCDO c1, p2, v500, z10, tool1, doGlue, 1;
MoveLSync p1, v1000, z30, tool2, "proc1";
MoveJSync p1, vmax, z30, tool2, "proc2";
MoveCSync c1, p2, v500, z30, tool2, "proc3";
TriggL p1, v500, gunon, fine, gun1;
TriggL \Conc, p1, v500, gunon\T2:=gunoff, z10, gun1\WObj:=wobj1\Corr;
TriggJ p1, v500, trigg1, fine, gun1;
TriggC cirp, p1, v500, gunon, fine, gun1;
TriggLIOs p3, v500\TriggData1:=myio, z50, tool1;
TriggJIOs p3, v500\TriggData2:=mystr, z50, tool1;
SearchL di1, sp, p10, v100, probe;
SearchL \Stop, di2\PosFlank, sp, p10, v100, tool1\WObj:=wobj1;
SearchL \Sup, di1\Flanks, sp, p10, v100\V:=80, probe;
SearchJ di1, sp, p10, v100, probe;
SearchC \PStop, di1, sp, cirpoint, p10, v100, probe;
SearchExtJ \SStop, di1\NegFlank, jsp, jpos10, vrot20;
AccSet 50, 100;
AccSet 100, 100\FinePointRamp:=50;
VelSet 50, 800;
SpeedRefresh 80;
ConfJ \On;
ConfL \Off;
SingArea \Wrist;
SingArea \LockAxis4;
SingArea \Off;
PathAccLim TRUE\AccMax:=4, TRUE\DecelMax:=4;
PathAccLim FALSE\AccMax:=4, TRUE\DecelMax:=4;
PathAccLim FALSE, FALSE;
WorldAccLim \On:=3.5;
WorldAccLim \Off;
GripLoad piece1;
CirPathMode \PathFrame;
CirPathMode \Wrist56;
CirPathMode;
MotionSup \On\TuneValue:=200;
MotionSup \Off;
CornerPathWarning FALSE;
PDispOn \ExeP:=p10, p20, tool1;
PDispOn \Rot\ExeP:=p10, p20, tool1\WObj:=wobj1;
PDispSet xp100;
PDispOff;
EOffsOn \ExeP:=p10, p11;
EOffsSet eax_a_offs;
EOffsOff;
TuneServo MHA160R1, 1, 110\Type:=TUNE_KP;
TuneReset;
SoftAct 3, 20;
SoftAct \MechUnit:=orbit1, 1, 40\Ramp:=120;
SoftDeact;
SoftDeact \Ramp:=150;
ActUnit orbit_a;
DeactUnit track_motion;
MechUnitLoad IRBP_L, 1, load0;
StopMove;
StopMove \Quick;
StartMove;
StartMove \AllMotionTasks;
StartMoveRetry;
StopMoveReset;
StorePath;
StorePath \KeepSync;
RestoPath;
ClearPath;
SetSysData tool5;
SetSysData tool0\ObjectName:="tool6";
GetSysData curtoolvalue\ObjectName:=curtoolname;
TriggIO gunon, 0.2\Time\DOp:=gun, 1;
TriggIO gunon, 10\DOp:=gun, 1;
TriggEquip gunon, 10, 0.1\DOp:=gun, 1;
TriggInt trigg1, 5, intno1;
TriggInt trigg1, 0.1\Time, intno1;
CorrCon sensor_corr;
CorrDiscon sensor_corr;
CorrWrite sensor_corr, offset1;
CorrClear;
WaitTime 0.5;
WaitTime \InPos, 0;
WaitUntil di4 = 1;
WaitUntil \InPos, di4 = 1\MaxTime:=5\TimeFlag:=timeout;
WaitUntil ready\PollRate:=0.04;
WaitDI di4, 1;
WaitDI di4, 1\MaxTime:=2\TimeFlag:=flag1;
WaitDO do4, 1;
WaitGI gi1, 5;
WaitGI gi1\NOTEQ, 0\MaxTime:=2;
WaitGO go1\GT, 10;
WaitAI ai1\GT, 5;
WaitAO ao1\LT, 5\MaxTime:=4;
WaitRob \InPos;
WaitRob \ZeroSpeed;
WaitTestAndSet semPers;
SetDO do15, 1;
SetDO \SDelay:=0.2, weld, high;
SetDO \Sync, do1, 0;
Set do15;
Reset do15;
PulseDO do15;
PulseDO \PLength:=1.0, ignition;
PulseDO \High, do3;
InvertDO do15;
SetGO go2, 12;
SetAO ao2, 5.5;
IOEnable "cell1", 5;
IODisable "cell1", 5;
IOBusStart "DeviceNet1";
IOBusState "DeviceNet1", bstate\Phys;
AliasIO "config_do", alias_do;
AliasIOReset alias_do;
Stop;
Stop \NoRegain;
Stop \AllMoveTasks;
Break;
Exit;
ExitCycle;
SystemStopAction \Stop;
CallByVar "proc", reg1;
Load \Dynamic, diskhome \File:="PART_A.MOD";
Load "HOME:/PART_B.MOD";
UnLoad diskhome \File:="PART_A.MOD";
UnLoad \Save, "HOME:/PART_B.MOD";
StartLoad \Dynamic, diskhome \File:="PART_B.MOD", load1;
WaitLoad load1;
CancelLoad load1;
EraseModule "PART_A";
Save "PART_B";
Save \TaskName:="T_ROB2", "PART_B"\FilePath:="HOME:/DOORDIR/PART_B.MOD";
RaiseToUser \Continue;
RaiseToUser \BreakOff\ErrorNumber:=ERR_MYERR;
ErrWrite "PLC error", "Fatal error in PLC"\RL2:="Call service";
ErrWrite \W, "Search error", "No hit for the first search";
ErrLog 4800, arg, arg, arg, arg, arg;
ErrLog 4801\W, "a", "b", "c", "d", "e";
ErrRaise "ERR_MY", 4800, "a", "b", "c", "d", "e";
BookErrNo ERR_MYERR;
SkipWarn;
ResetRetryCount;
Incr reg1;
Incr nCount{2};
Decr reg1;
Add reg1, 3;
Add reg1, -reg2;
Clear reg1;
BitSet data1, 8;
BitClear data1, 8;
SetDataVal "reg"+ValToStr(ReadNum(mycom)), value;
SetDataVal "flag1"\TaskName:="T_ROB1", TRUE;
GetDataVal "reg"+ValToStr(ReadNum(mycom)), value;
SetAllDataVal "mydata"\TypeMod:="mytypes"\Hidden, mydata0;
ClearRawBytes raw_data;
ClearRawBytes raw_data\FromIndex:=5;
CopyRawBytes from_raw, 1, to_raw, 3\NoOfBytes:=10;
PackRawBytes integer, raw_data, 1\IntX:=DINT;
PackRawBytes float, raw_data, RawBytesLen(raw_data)+1\Float4;
PackRawBytes "abc", raw_data, 9\ASCII;
PackRawBytes byte1, raw_data\Network, 17\Hex1;
UnpackRawBytes raw_data, 1, integer\IntX:=DINT;
UnpackRawBytes raw_data\Network, 5, float\Float4;
UnpackRawBytes raw_data, 9, text\ASCII:=3;
IDelete feeder_low;
IEnable;
IDisable;
ISleep sig1int;
IWatch sig1int;
ISignalDI di1, 1, sig1int;
ISignalDI \Single, di1, 1, sig1int;
ISignalDO do1, 0, sig1int;
ISignalGI gi1, sig1int;
ISignalGO \SingleSafe, go1, sig1int;
ISignalAI ai1, AIO_BETWEEN, 1.5, 0.5, 0, sig1int;
ISignalAI \Single, ai1, AIO_OUTSIDE, 1.5, 0.5, 0.1\DPos, sig1int;
ISignalAO ao1, AIO_BETWEEN, 1.5, 0.5, 0, sig1int;
ITimer 60, timeint;
ITimer \Single, 60, timeint;
IPers counter, int1;
IError COMMON_ERR, TYPE_ALL, err_int;
IError MOTION_ERR\ErrorId:=50024, TYPE_ERR, err_int;
GetTrapData err_data;
TPWrite "Execution started";
TPWrite "No of produced parts="\Num:=reg1;
TPWrite "Position: "\Pos:=p1;
TPErase;
TPShow TP_LATEST;
TPReadNum reg1, "How many units should be produced?";
TPReadNum reg1, "How many?"\MaxTime:=10\BreakFlag:=errvar;
TPReadDnum value, "Count?"\DIBreak:=di5;
TPReadFK reg1, "More ?", stEmpty, stEmpty, stEmpty, "Yes", "No";
TPReadFK answer, "Go on?", "", "", "", "Yes", "No"\MaxTime:=30\DIBreak:=di5\BreakFlag:=errvar;
UIMsgBox "Continue the program ?";
UIMsgBox \Header:="Cell", "Continue?"\MsgLine2:="Press OK"\Buttons:=btnOKCancel\Icon:=iconInfo\Result:=answer;
UIShow "TpsViewMyApp.gtpu.dll", "ABB.Robotics.SDK.Views.TpsViewMyApp"\InstanceID:=myinstance\Status:=mystatus;
ClkReset clock1;
ClkStart clock1;
ClkStop clock1;
Open "HOME:" \File:= "LOGFILE1.DOC", logfile\Write;
Open "com1:", printer\Bin;
Open "HOME:/dat.txt", infile\Read;
Close logfile;
Rewind iodev1;
ClearIOBuff channel1;
Write logfile, "Execution started";
Write logfile, "No of produced parts="\Num:=reg1;
Write logfile, "Pos: "\Pos:=p1\NoNewLine;
WriteBin channel2, text_buffer, 10;
WriteStrBin channel2, "Hello";
WriteAnyBin channel1, quit;
WriteRawBytes io_device, raw_data\NoOfBytes:=RawBytesLen(raw_data);
ReadAnyBin channel1, next_target;
ReadAnyBin channel1, next_target\TimeOut:=0.1;
ReadRawBytes io_device, raw_data_in\Time:=1;
MakeDir "HOME:/newdir";
RemoveDir "HOME:/mydir";
RemoveFile "HOME:/mydir/myfile.log";
RenameFile "HOME:/a.log", "HOME:/b.log";
CopyFile "HOME:/a.log", "HOME:/c.log";
OpenDir directory, "HOME:";
CloseDir directory;
SyncMoveOn sync1, task_list;
SyncMoveOn sync2, task_list\TimeOut:=60;
SyncMoveOff sync2;
SyncMoveOff sync3\TimeOut:=60;
SyncMoveUndo;
SyncMoveSuspend;
SyncMoveResume;
WaitSyncTask sync1, task_list;
WaitSyncTask \InPos, sync1, task_list\TimeOut:=60;
SocketCreate socket1;
SocketCreate udp_sock\UDP;
SocketConnect socket1, "192.168.0.1", 1025;
SocketConnect socket1, "192.168.0.1", 1025\Time:=30;
SocketBind server_socket, "192.168.0.1", 1025;
SocketListen server_socket;
SocketAccept server_socket, client_socket;
SocketAccept server_socket, client_socket\ClientAddress:=client_ip\Time:=WAIT_MAX;
SocketSend socket1\Str:="Hello server";
SocketSend socket1\RawData:=raw_data\NoOfBytes:=8;
SocketSend socket1\Data:=data_buffer\NoOfBytes:=5;
SocketSendTo udp_sock, "192.168.0.2", 3000\Str:="Hi";
SocketReceive socket1\Str:=str_data;
SocketReceive socket1\Str:=str_data\NoRecBytes:=n\Time:=10;
SocketReceive socket1\RawData:=raw_data\ReadNoOfBytes:=4;
SocketReceiveFrom udp_sock\Str:=msg, remote_ip, remote_port;
SocketClose socket1;
RMQFindSlot myrmqslot, "RMQ_T_ROB2";
RMQSendMessage myrmqslot, data2;
RMQSendMessage myrmqslot, data2\UserDef:=1;
RMQGetMessage rmqmessage1;
RMQGetMsgData rmqmessage1, data;
RMQGetMsgHeader rmqmessage1\Header:=header1\SenderId:=sender1;
RMQReadWait myrmqmsg\TimeOut:=30;
RMQEmptyQueue;
RMQSendWait myrmqslot, mydata, myrmqmsg, mydata\TimeOut:=5;
IRMQMessage mynum, msg_int;
CamReqImage mycamera;
CamReqImage mycamera\SceneId:=2\KeepOldResults;
CamGetResult mycamera, mycamtarget;
CamGetResult mycamera, mycamtarget\MaxTime:=5;
CamSetProgramMode mycamera;
CamSetRunMode mycamera;
CamLoadJob mycamera, "myjob.job";
CamLoadJob mycamera, "myjob.job"\MaxTime:=10;
CamStartLoadJob mycamera, "myjob.job";
CamWaitLoadJob mycamera;
CamFlush mycamera;
CamSetExposure mycamera\ExposureTime:=10;
CamSetParameter mycamera, "Pattern_1.Tool_Enabled"\Bool:=TRUE;
CamGetParameter mycamera, "Pattern_1.Tool_Enabled"\Bool:=enabled;
g_Init;
g_Init \maxSpd:=20\holdForce:=15\Calibrate;
g_Calibrate;
g_GripIn;
g_GripIn \holdForce:=14;
g_GripIn \holdForce:=20\targetPos:=5\NoWait;
g_GripOut;
g_GripOut \holdForce:=10\NoWait;
g_MoveTo 10;
g_MoveTo 20\NoWait;
g_Stop;
g_JogIn;
g_JogOut;
g_BlowOn1;
g_BlowOff1;
g_VacuumOn1;
g_VacuumOff1;
ArcL \On, p10, v100, seam1, weld1\Weave:=weave1, fine, torch1\WObj:=wobj1;
ArcL p20, v100, seam1, weld1, z10, torch1;
ArcL \Off, p30, v100, seam1, weld1, fine, torch1\Track:=track1\SeamName:="s1";
ArcLStart pStart, v100, seam1, weld1, fine, torch1;
ArcLStart pStart\ID:=10, v1000, seam1, weld1\Weave:=weave1, fine, torch1\WObj:=wobj1\Track:=track1\SeamName:="s1";
ArcLEnd pEnd, v100, seam1, weld1, fine, torch1\WObj:=wobj1;
ArcC \On, cp, p10, v100, seam1, weld1, fine, torch1;
ArcCStart cp, p10, v100, seam1, weld1, fine, torch1;
ArcCEnd cp, p10, v100, seam1, weld1, fine, torch1;
ArcRefresh;
ArcKill;
DispL \On, p1, v250, bead1, z30, tool1;
DispL \Off, p2, v250, bead2, fine, tool1\WObj:=wobj1;
DispC \On, cp, p3, v250, bead1, z30, tool1;
FCAct tPolish;
FCAct tPolish\WObj:=wobjPanel;
FCDeact;
FCCalib load1;
FCPressL pEnd, vTravel, 50, fine, tPolish\WObj:=wobjPanel;
FCPressC cp, pEnd, v20, 30, z5, tPolish;
FCPress1LStart pStart, v10, z5, tPolish\WObj:=wobjPanel;
FCPressEnd pLift, v10, fine, tPolish;
FCRefStart;
FCRefStop;
WaitWObj wobj_cnv1;
WaitWObj wobj_cnv1\RelDist:=500;
WaitWObj wobj_cnv1\RelDist:=0\MaxTime:=0.1\TimeFlag:=flag1;
DropWObj wobj_cnv1;
IndAMove Station_A, 2\ToAbsPos:=p4, 20;
IndAMove Station_A, 2\ToAbsNum:=90, 20\Ramp:=50;
IndCMove Station_A, 2, -30.5;
IndDMove Station_A, 2, -30, 20;
IndRMove Station_A, 2\ToRelPos:=p5\Short, 20;
IndReset Station_A, 2;
IndReset Station_A, 1\RefNum:=0\Short;
"""

FUNCTION_CALLS = r"""
Abs(reg1)
AbsDnum(dval)
Sqrt(x*x+y*y)
Exp(x)
Pow(3, 2)
Sin(angle)
Cos(angle)
Tan(angle)
ASin(value)
ACos(value)
ATan(value)
ATan2(y, x)
Round(reg1\Dec:=1)
Round(reg1)
Trunc(reg1\Dec:=2)
NumToDnum(reg1)
DnumToNum(dval\Integer)
Dim(arr, 1)
Present(PartNo)
Offs(p2, 0, 0, 10)
RelTool(p1, 0, 0, 100\Rz:=25)
RelTool(p1, 0, 0, 0\Rx:=10\Ry:=20)
OrientZYX(45, 0, 0)
EulerZYX(\X, object.rot)
EulerZYX(\Z, p1.rot)
NOrient(o)
PoseInv(frame1)
PoseMult(pose1, pose2)
PoseVect(pose1, pos1)
VectMagn(vector)
DotProd(v1, v2)
CrossProd(v1, v2)
Distance(p1.trans, p2.trans)
DefFrame(p1, p2, p3)
DefFrame(p1, p2, p3\Origin:=1)
DefDFrame(p1, p2, p3, p4, p5, p6)
MirPos(p1, mirror)
MirPos(p1, mirror\WObj:=wobj1\MirY)
CalcJointT(p1, tool1)
CalcJointT(\UseCurWObjPos, p1, tool1\WObj:=wobj1)
CalcJointT(p1, tool1\ErrorNumber:=myerrnum)
CalcRobT(jointpos1, tool1\WObj:=wobj1)
CRobT()
CRobT(\Tool:=tool1\WObj:=wobj0)
CRobT(\TaskName:="T_ROB2"\Tool:=tool1)
CJointT()
CJointT(\TaskRef:=T_ROB1Id)
CPos(\Tool:=tool1\WObj:=wobj0)
CTool()
CWObj()
CSpeedOverride()
CSpeedOverride(\CTask)
ReadMotor(2)
ReadMotor(\MecUnit:=STN1, 1)
CorrRead()
IsMechUnitActive(SpotWeldGun)
GetMecUnitName(ROB_1)
TaskRunMec()
TaskRunRob()
GetTaskName()
GetTaskName(\TaskNo:=taskno)
RobOS()
OpMode()
RunMode()
RunMode(\Main)
IsStopStateEvent(\PPMoved)
IsSysId("6400-1234")
DInput(di1)
DOutput(do1)
GInput(gi1)
GOutput(go1)
GInputDnum(gi1)
GOutputDnum(go1)
AInput(ai1)
AOutput(ao1)
TestDI(di2)
ValidIO(di1)
IOUnitState("UNIT1")
IOUnitState("UNIT1"\Phys)
NumToStr(reg1, 2)
NumToStr(reg1, 0\Exp)
DnumToStr(dval, 2)
StrToVal("3.85", nval)
ValToStr(p)
StrLen(str)
StrPart("Robotics", 1, 5)
StrFind(str, 1, STR_WHITE)
StrFind(str, 1, STR_DIGIT\NotInSet)
StrMatch(str, 1, "xyz")
StrMemb(str, 2, "aeiou")
StrOrder("FIRST", "SECOND", STR_UPPER)
StrMap("Robotics", "abcdefghijklmnopqrstuvwxyz", "ABCDEFGHIJKLMNOPQRSTUVWXYZ")
StrToByte("10"\Hex)
StrToByte("A"\Char)
ByteToStr(10\Hex)
ByteToStr(data1)
DecToHex("99999999")
HexToDec("5F5E0FF")
BitAnd(data1, data2)
BitOr(data1, data2)
BitXOr(data1, data2)
BitNeg(data1)
BitLSh(data1, 3)
BitRSh(data1, 3)
BitCheck(data1, 5)
Type(refdata)
Type(refdata\BaseName)
IsPers(p)
IsVar(p)
ArgName(par1)
TestAndSet(tproc_lock)
RawBytesLen(raw_data)
GetNextSym(name, block\Recursive)
CDate()
CTime()
GetTime(\WDay)
GetTime(\Hour)
ClkRead(clock1)
ClkRead(clock1\HighRes)
ReadNum(infile)
ReadNum(infile\Delim:=","\Time:=10)
ReadStr(infile)
ReadStr(infile\Time:=5)
ReadBin(channel2)
ReadBin(channel2\Time:=0.1)
ReadStrBin(channel2, 10)
ReadDir(directory, filename)
IsFile("HOME:/mydir"\Directory)
IsFile("HOME:/f.txt")
FileSize("HOME:/f.txt")
FSSize("HOME:/spy.log"\Free)
ModExist("mymod")
ModTime("mymod")
UIMessageBox(\Header:="Cycle"\Message:="Continue?"\Buttons:=btnOKCancel\Icon:=iconInfo)
UIMessageBox(\MsgArray:=lines\BtnArray:=mybuttons)
UINumEntry(\Header:="Parts"\Message:="How many?"\InitValue:=5\MinValue:=1\MaxValue:=10\AsInteger)
UIDnumEntry(\Header:="Parts"\InitValue:=5)
UINumTune(\Header:="Tune"\Message:="Offset?", 0.5, 0.1\MinValue:=0\MaxValue:=1)
UIAlphaEntry(\Header:="Name"\Message:="Which part?"\InitString:="A1")
UIListView(\Result:=res\Header:="Pick"\Buttons:=btnOKCancel, list\DefaultIndex:=1)
UIClientExist()
IsSyncMoveOn()
SocketGetStatus(socket1)
CamGetName(mycamera)
CamGetLoadedJob(mycamera)
CamNumberOfResults(mycamera)
CamNumberOfResults(mycamera\SceneId:=1)
g_GetPos()
g_GetState()
g_IsCalibrated()
FCGetForce()
FCIsForceMode()
IndInpos(Station_A, 2)
IndSpeed(Station_A, 2\InSpeed)
"""


def _calls(text: str) -> list[tuple[str, str]]:
    out = []
    for line in text.strip().splitlines():
        line = line.strip()
        if not line:
            continue
        m = re.fullmatch(r"([A-Za-z_]\w*)\s*(.*)", line)
        assert m, line
        out.append((m.group(1), m.group(2)))
    return out


@pytest.mark.parametrize(("name", "args"), _calls(CALLS) + _calls(FUNCTION_CALLS))
def test_match_arguments_call_as_written(name, args):
    b = lookup(name)
    assert b is not None, f"{name} is not in the table"
    assert b.kind is (Kind.FUNCTION if args.startswith("(") else Kind.INSTRUCTION)
    matched = match_arguments(b, call_args(args))
    for p in b.required:
        assert p.name in matched
    if b.complete:
        assert all(b.param(k) is not None for k in matched)


def test_calls_cover_most_of_the_table():
    written = {
        n.lower() for n, _ in _calls(CALLS + MORE_CALLS) + _calls(FUNCTION_CALLS + MORE_FUNCTION_CALLS)
    }
    table = {b.name.lower() for b in bi.all_builtins()}
    assert written <= table
    assert len(written) / len(table) > 0.85, sorted(table - written)


@pytest.mark.parametrize("b", bi.all_builtins(), ids=lambda b: b.name)
def test_match_arguments_generated_calls(b):
    """Every entry takes its required arguments in place, and then every optional one too
    (the first of each exclusive group)."""
    required = [(None, f"a{k}") for k, _ in enumerate(b.required)]
    minimal = required + [
        (g[0].name, None if g[0].kind is ParamKind.SWITCH else "x") for g in b.required_groups
    ]
    assert set(match_arguments(b, minimal)) == {p.name for p in b.required} | {
        g[0].name for g in b.required_groups
    }
    full = list(required)
    taken: set[int] = set()
    for p in b.params:
        if p.required or (p.group is not None and p.group in taken):
            continue
        if p.group is not None:
            taken.add(p.group)
        full.append((p.name, None if p.kind is ParamKind.SWITCH else "x"))
    assert len(match_arguments(b, full)) == len(full)


# ---------------------------------------------------------------- the rules fail when they should
def test_match_arguments_required_missing():
    with pytest.raises(ArgumentError, match=r"MoveL needs Tool \(tooldata\)"):
        match_arguments(lookup("MoveL"), call_args("p10, v100, z10"))


def test_match_arguments_too_many():
    with pytest.raises(ArgumentError, match="takes 4 argument"):
        match_arguments(lookup("MoveL"), call_args("p10, v100, z10, tool0, wobj1"))


def test_match_arguments_unknown_optional():
    with pytest.raises(ArgumentError, match=r"MoveJ has no argument \\Corr"):
        match_arguments(lookup("MoveJ"), call_args(r"p10, v100, z10, tool0\Corr"))


def test_match_arguments_exclusive_group():
    with pytest.raises(ArgumentError, match=r"\\V and \\T exclude each other"):
        match_arguments(lookup("MoveL"), call_args(r"p10, v100\V:=100\T:=3, z10, tool0"))
    with pytest.raises(ArgumentError, match="exclude each other"):
        match_arguments(lookup("SearchL"), call_args(r"\Stop\PStop, di1, sp, p10, v100, probe"))


def test_match_arguments_required_group():
    with pytest.raises(ArgumentError, match=r"ConfL needs one of \\On or \\Off"):
        match_arguments(lookup("ConfL"), [])
    with pytest.raises(ArgumentError, match="exclude each other"):
        match_arguments(lookup("ConfJ"), [("On", None), ("Off", None)])


def test_match_arguments_switch_and_value():
    with pytest.raises(ArgumentError, match="is a switch"):
        match_arguments(lookup("MoveL"), call_args(r"\Conc:=1, p10, v100, z10, tool0"))
    with pytest.raises(ArgumentError, match="needs a value"):
        match_arguments(lookup("MoveL"), call_args(r"p10, v100, z10, tool0\WObj"))


def test_match_arguments_twice():
    with pytest.raises(ArgumentError, match="given twice"):
        match_arguments(lookup("MoveL"), call_args(r"p10, v100, z10, tool0\WObj:=w1\WObj:=w2"))


def test_match_arguments_case_insensitive_names():
    m = match_arguments(lookup("movel"), call_args(r"p10, v100, z10, tool0\wobj:=w1"))
    assert m["WObj"] == "w1"


def test_match_arguments_named_required_any_order():
    m = match_arguments(lookup("MoveL"), call_args("Tool:=t1, ToPoint:=p1, Speed:=v1, Zone:=z1"))
    assert m == {"ToPoint": "p1", "Speed": "v1", "Zone": "z1", "Tool": "t1"}


def test_match_arguments_partial_entry_is_lenient():
    b = lookup("g_GripIn")
    assert not b.complete
    m = match_arguments(b, call_args(r"\holdForce:=10\Chan:=2"))
    assert m == {"holdForce": "10", "Chan": "2"}
    m = match_arguments(lookup("FCSupvForce"), call_args("-10, 10, -10, 10, -50, 50"))
    assert m["#1"] == "-10" and m["#6"] == "50"


def test_match_arguments_moveldo_as_documented():
    m = match_arguments(lookup("MoveLDO"), call_args(r"p1, v1000\T:=2, z10, tool1\WObj:=wobj1, doGrip, 1"))
    assert (m["ToPoint"], m["Tool"], m["WObj"], m["Signal"], m["Value"]) == (
        "p1",
        "tool1",
        "wobj1",
        "doGrip",
        "1",
    )


def test_match_arguments_pathacclim_as_documented():
    m = match_arguments(lookup("PathAccLim"), call_args(r"FALSE \AccMax:=4, TRUE \DecelMax:=4"))
    assert m == {"AccLim": "FALSE", "AccMax": "4", "DecelLim": "TRUE", "DecelMax": "4"}


def test_match_arguments_conditional_left_out_when_absent():
    # MoveL p1, v100, z10, tool0 \WObj?wo: the caller gives \WObj only where wo is present
    assert "WObj" not in match_arguments(lookup("MoveL"), call_args("p1, v100, z10, tool0"))


# ---------------------------------------------------------------- effects
def test_motion_instructions_name_their_roles():
    n_moves = 0
    for b in bi.all_builtins(kind=Kind.INSTRUCTION):
        if b.effect is not Effect.MOVE:
            assert b.motion is None
            continue
        assert b.motion is not None, b.name
        n_moves += 1
        m = b.motion
        if m.kind in bi.ROBOT_MOTIONS:
            assert m.target and m.speed and m.tool, b.name
            assert m.zone or m.search, b.name
            assert m.wobj == "WObj", b.name
        if m.kind is MotionKind.CIRCULAR:
            assert m.circle and m.circle != m.target, b.name
        for role in (m.target, m.circle, m.speed, m.zone, m.tool, m.wobj, m.time, m.velocity, m.zone_size):
            assert role is None or b.param(role) is not None, (b.name, role)
    assert n_moves >= 35


@pytest.mark.parametrize(
    ("name", "kind", "target", "circle", "time"),
    [
        ("MoveL", MotionKind.LINEAR, "ToPoint", None, "T"),
        ("MoveJ", MotionKind.JOINT, "ToPoint", None, "T"),
        ("MoveC", MotionKind.CIRCULAR, "ToPoint", "CirPoint", "T"),
        ("MoveAbsJ", MotionKind.ABSJOINT, "ToJointPos", None, "T"),
        ("MoveLDO", MotionKind.LINEAR, "ToPoint", None, "T"),
        ("TriggC", MotionKind.CIRCULAR, "ToPoint", "CirPoint", "T"),
        ("SearchL", MotionKind.LINEAR, "ToPoint", None, "T"),
        ("SearchC", MotionKind.CIRCULAR, "ToPoint", "CirPoint", "T"),
        ("ArcL", MotionKind.LINEAR, "ToPoint", None, "T"),
        ("ArcC", MotionKind.CIRCULAR, "ToPoint", "CirPoint", "T"),
        ("MoveExtJ", MotionKind.EXTERNAL, "ToJointPos", None, "T"),
    ],
)
def test_motion_roles(name, kind, target, circle, time):
    m = lookup(name).motion
    assert (m.kind, m.target, m.circle, m.time) == (kind, target, circle, time)


def test_search_and_process_flags():
    assert lookup("SearchL").motion.search and lookup("SearchL").param("SearchPoint").runtime
    assert lookup("ArcL").motion.process and lookup("ArcL").option == "Arc"
    assert not lookup("MoveL").motion.process and not lookup("MoveL").motion.search


@pytest.mark.parametrize(
    ("name", "effect"),
    [
        ("WaitTime", Effect.TIME),
        ("WaitDI", Effect.WAIT),
        ("WaitUntil", Effect.WAIT),
        ("WaitSyncTask", Effect.WAIT),
        ("SocketReceive", Effect.WAIT),
        ("AccSet", Effect.SETTING),
        ("VelSet", Effect.SETTING),
        ("ConfJ", Effect.SETTING),
        ("ConfL", Effect.SETTING),
        ("SingArea", Effect.SETTING),
        ("PathAccLim", Effect.SETTING),
        ("SpeedRefresh", Effect.SETTING),
        ("SetDO", Effect.IO),
        ("PulseDO", Effect.IO),
        ("TPWrite", Effect.NONE),
        ("BookErrNo", Effect.NONE),
    ],
)
def test_effects(name, effect):
    assert lookup(name).effect is effect


def test_waittime_duration_and_waits_max_time():
    assert lookup("WaitTime").duration == "Time"
    assert lookup("WaitDI").max_time == "MaxTime"
    assert lookup("WaitSyncTask").max_time == "TimeOut"


@pytest.mark.parametrize(
    "name",
    ["CRobT", "CJointT", "CPos", "DInput", "GInput", "AInput", "TestDI", "ReadNum", "ReadStr", "ClkRead",
     "CDate", "CTime", "UINumEntry", "SocketGetStatus", "CamNumberOfResults", "g_GetPos", "FCGetForce"],
)  # fmt: skip
def test_runtime_functions(name):
    b = lookup(name)
    assert b.kind is Kind.FUNCTION and b.runtime and b.returns


@pytest.mark.parametrize("name", ["Offs", "RelTool", "Abs", "NumToStr", "StrPart", "OrientZYX", "PoseMult"])
def test_pure_functions_are_not_runtime(name):
    assert not lookup(name).runtime


@pytest.mark.parametrize(
    ("name", "param"),
    [("TPReadNum", "TPAnswer"), ("TPReadFK", "TPAnswer"), ("SocketReceive", "Str"),
     ("CamGetResult", "CamTarget"), ("SearchL", "SearchPoint"), ("ReadAnyBin", "Data"),
     ("RMQGetMsgData", "Data")],
)  # fmt: skip
def test_runtime_writes(name, param):
    b = lookup(name)
    assert b.param(param).runtime and b.param(param) in b.writes


def test_options_named():
    options = {b.option for b in bi.all_builtins()}
    for option in ("SmartGripper", "Integrated Vision", "Socket Messaging", "Arc", "Dispense",
                   "Force Control", "Multitasking", "Conveyor Tracking"):  # fmt: skip
        assert option in options
    assert lookup("MoveL").option is None
    assert lookup("g_GripIn").option == "SmartGripper"
    assert lookup("SyncMoveOn").option == "Multitasking"


# ---------------------------------------------------------------- data types
def test_data_type_records():
    assert data_type("ROBTARGET").components == (
        ("trans", "pos"), ("rot", "orient"), ("robconf", "confdata"), ("extax", "extjoint"),
    )  # fmt: skip
    assert [c for c, _ in data_type("tooldata").components] == ["robhold", "tframe", "tload"]
    assert [c for c, _ in data_type("speeddata").components] == ["v_tcp", "v_ori", "v_leax", "v_reax"]
    assert len(data_type("zonedata").components) == 7
    assert [c for c, _ in data_type("wobjdata").components] == [
        "robhold",
        "ufprog",
        "ufmec",
        "uframe",
        "oframe",
    ]
    assert data_type("signaldi").value is False
    assert data_type("errnum").alias_of == "num"
    assert data_type("no_such_type") is None


def test_data_types_agree_with_the_interpreters_records():
    from joulepath.rapid.values import BUILTIN_RECORDS

    for name, comps in BUILTIN_RECORDS.items():
        if name == "stoppointdata":  # the interpreter flattens inposdata into it
            continue
        assert data_type(name).components == comps, name


# ---------------------------------------------------------------- table integrity
def test_table_names_unique():
    names = [b.name.lower() for b in bi.all_builtins()] + [t.name.lower() for t in bi.all_data_types()]
    assert len(names) == len(set(names))


def test_every_param_type_is_known():
    known = {t.name for t in bi.all_data_types()} | bi.BASE_TYPES
    for b in bi.all_builtins():
        for p in b.params:
            for t in p.types:
                assert t in known, (b.name, p.name, t)
        if b.returns:
            assert b.returns in known, b.name
    for t in bi.all_data_types():
        for comp, type_ in t.components:
            assert type_ in known, (t.name, comp)
        if t.alias_of:
            assert t.alias_of in known, t.name


def test_every_entry_has_a_source():
    assert all(b.source for b in bi.all_builtins())
    assert all(t.source for t in bi.all_data_types())


def test_table_counts():
    assert len(bi.all_builtins(kind=Kind.INSTRUCTION, option=None)) >= 150
    assert len(bi.all_builtins(kind=Kind.FUNCTION, option=None)) >= 100
    assert len(bi.all_data_types()) >= 60


def test_lookup_case_insensitive_and_unknown():
    assert lookup("MOVEL") is lookup("movel") is lookup("MoveL")
    assert lookup("NotAnInstruction") is None


# ---------------------------------------------------------------- the notation
def test_parse_signature_kinds_and_groups():
    ps = parse_signature(r"[\Conc] ToPoint:robtarget [\V:num|\T:num] Tool:tooldata& Data:byte{*}! <\A|\B>")
    assert [(p.name, p.kind) for p in ps] == [
        ("Conc", ParamKind.SWITCH), ("ToPoint", ParamKind.REQUIRED), ("V", ParamKind.OPTIONAL),
        ("T", ParamKind.OPTIONAL), ("Tool", ParamKind.REQUIRED), ("Data", ParamKind.REQUIRED),
        ("A", ParamKind.SWITCH), ("B", ParamKind.SWITCH),
    ]  # fmt: skip
    assert [p.group for p in ps] == [None, None, 0, 0, None, None, 1, 1]
    assert ps[4].writes and not ps[4].runtime
    assert ps[5].array and ps[5].runtime


@pytest.mark.parametrize(
    "bad", [r"ToPoint", r"[ToPoint:robtarget]", r"\Conc", r"A:num A:num", r"A:num ,B:num"]
)
def test_parse_signature_refuses_bad_text(bad):
    with pytest.raises(ValueError, match="signature"):
        parse_signature(bad)


MORE_CALLS = r"""
WaitDI di1, 1\Visualize\Header:="Waiting"\MsgArray:=["a", "b"]\Icon:=iconInfo;
WaitUntil ready = TRUE\PollRate:=0.1\Visualize\Header:="Waiting"\Message:="Buffer full";
SpeedLimAxis STN_1, 1, 10;
SpeedLimCheckPoint 400;
ReadCfgData "/MOC/MOTOR_CALIB/rob1_1", "cal_offset", offset1;
WriteCfgData "/MOC/MOTOR_CALIB/rob1_1", "cal_offset", offset1;
WZBoxDef \Inside, volume, corner1, corner2;
WZCylDef \Outside, volume, centre, 100, 200;
WZSphDef \Inside, volume, centre, 50;
WZHomeJointDef \Inside, joint_space, home_pos, delta_pos;
WZLimJointDef \Outside, joint_space, low_pos, high_pos;
WZDOSet \Temp, service \Inside, volume, do_service, 1;
WZDOSet \Stat, service \Before, volume, do_service, 0;
WZLimSup \Stat, max_workarea, volume;
WZEnable wz_temp;
WZDisable wz_temp;
WZFree wz_temp;
EGMGetId egm_id;
EGMReset egm_id;
EGMSetupUC ROB_1, egm_id, "default", "UCdevice"\Joint;
EGMSetupUC ROB_1, egm_id, "default", "UCdevice"\Pose\CommTimeout:=0.1;
EGMActJoint egm_id\Tool:=tool0\WObj:=wobj0\J1:=limits\J2:=limits\LpFilter:=20\SampleRate:=4;
EGMActPose egm_id\Tool:=tool1\WObj:=wobj1, corr_frame, EGM_FRAME_WOBJ, sens_frame, EGM_FRAME_WOBJ\x:=limits\y:=limits;
EGMRunJoint egm_id, EGM_STOP_HOLD\J1\J2\J3\J4\J5\J6\CondTime:=20\RampInTime:=0.05;
EGMRunPose egm_id, EGM_STOP_RAMP_DOWN\x\y\z\CondTime:=10\RampOutTime:=0.5;
EGMStop egm_id, EGM_STOP_HOLD\RampOutTime:=0.5;
EGMStreamStart egm_id\SampleRate:=4;
EGMStreamStop egm_id;
EGMMoveL egm_id, p20, v10, z5, tEGM\WObj:=wobj0;
EGMMoveC egm_id, c1, p20, v10, z5, tEGM;
ArcMoveAbsJ jStart, v800, z10, tWeldGun;
ArcMoveExtJ jTrack, vrot20, fine;
CSSAct CSS_XYZ\Stiffness:=50\AllowMove;
CSSDeact;
SetDataSearch "tooldata"\Object:="tool.*";
SetDataSearch "robtarget"\PersSym\VarSym\InMod:="mymod";
"""

MORE_FUNCTION_CALLS = r"""
MaxRobSpeed()
GetMotorTorque(4)
IsStopMoveAct(\FromMoveTask)
GetSysInfo(\LanIp)
EGMGetState(egm_id)
"""


@pytest.mark.parametrize(("name", "args"), _calls(MORE_CALLS) + _calls(MORE_FUNCTION_CALLS))
def test_match_arguments_more_calls_as_written(name, args):
    test_match_arguments_call_as_written(name, args)


def test_egm_run_is_a_guided_move():
    m = lookup("EGMRunPose").motion
    assert m.kind is MotionKind.GUIDED and m.target is None
    assert lookup("EGMMoveL").motion.kind is MotionKind.LINEAR


DNUM_AND_SYSTEM_CALLS = r"""
TriggCheckIO checkgrip, 100, airok, EQ, 1\StopMove, gateclosed;
PathResol 150;
ActEventBuffer;
DeactEventBuffer;
ResetPPMoved;
SpyStart "HOME:/spy.log";
SpyStop;
TryInt reg1;
SqrtDnum(dval)
PowDnum(dval, 2)
ATan2Dnum(dy, dx)
RoundDnum(dval\Dec:=2)
BitAndDnum(d1, d2)
BitLShDnum(d1, 3)
BitCheckDnum(d1, 5)
StrDigCalc(s1, OpAdd, s2)
StrDigCmp(s1, LT, s2)
RobName()
TaskIsActive("T_ROB1")
ExecHandler()
ExecLevel()
RemainingRetries()
PPMovedInManMode()
FileTime("HOME:/f.txt"\ModifyTime)
"""


@pytest.mark.parametrize(("name", "args"), _calls(DNUM_AND_SYSTEM_CALLS))
def test_match_arguments_dnum_and_system_calls(name, args):
    test_match_arguments_call_as_written(name, args)
