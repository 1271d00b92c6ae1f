MODULE Palletizing
    ! Palletizing on the IRB 120 (joulepath example). Parts arrive on the infeed at the
    ! right; the robot stacks them in a 2 x 3 pattern on the pallet in front of it. Each
    ! place is computed from the first one with Offs; the pallet is exchanged by the
    ! operator after six parts (idle time: the robot only waits).
    PERS tooldata tVacuum := [TRUE, [[0, 0, 100], [1, 0, 0, 0]], [0.5, [0, 0, 50], [1, 0, 0, 0], 0, 0, 0]];
    CONST jointtarget jHome := [[0, 0, 0, 0, 30, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pPick := [[175, -375, 140], [0, 0, 1, 0], [-1, 0, -1, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pPallet := [[320, 60, 120], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST num nPitchX := 60;
    CONST num nPitchY := 60;
    CONST num nApproach := 80;
    CONST num nGrip := 0.25;

    PROC main()
        MoveAbsJ jHome, v1000, fine, tVacuum;
        WHILE TRUE DO
            FOR row FROM 0 TO 1 DO
                FOR col FROM 0 TO 2 DO
                    PickPart;
                    PlacePart Offs(pPallet, row * nPitchX, col * nPitchY, 0);
                ENDFOR
            ENDFOR
            MoveAbsJ jHome, v1000, fine, tVacuum;
            TPWrite "Pallet full: exchange it";
            WaitTime 3; ! joulepath: idle
        ENDWHILE
    ENDPROC

    PROC PickPart()
        MoveJ Offs(pPick, 0, 0, nApproach), v1000, z50, tVacuum;
        MoveL pPick, v300, fine, tVacuum;
        SetDO doVacuum, 1;
        WaitTime nGrip;
        MoveL Offs(pPick, 0, 0, nApproach), v300, z20, tVacuum;
    ENDPROC

    PROC PlacePart(robtarget pPlace)
        MoveJ Offs(pPlace, 0, 0, nApproach), v1000, z50, tVacuum;
        MoveL pPlace, v300, fine, tVacuum;
        SetDO doVacuum, 0;
        WaitTime nGrip;
        MoveL Offs(pPlace, 0, 0, nApproach), v300, z20, tVacuum;
    ENDPROC
ENDMODULE
